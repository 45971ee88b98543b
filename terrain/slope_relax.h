// Slope relaxation of a height field, local and sparse: where the slope from a
// cell to one of its 8 neighbours exceeds the material's angle, a fraction of
// the excess moves from the higher cell to the lower (paper 000, 3.5, after
// Sumner, O'Brien & Hodgins 1999: delta h = sigma x excess). Shared by the
// stages that let loose material slide: marks' erosion (terrain/marks) uses it
// now; snow's stabilisation (snow/stabilise_grid) may move onto it.
//
// Only the cells in the active list are examined, and a pass activates the
// neighbours of whatever moved, so the work stays around the disturbance.
// Each pass is Jacobi-style: flows are worked out from the heights before the
// pass and then applied, so the result does not depend on the order of the
// list (a symmetric disturbance relaxes symmetrically). The excess of a pair
// is measured against the higher cell's rule: e = (h_c - h_n) - tan(theta) d,
// d = the distance between cell centres (dx, dy or the diagonal).
//
// Per pass a cell gives sigma x e to each steeper neighbour, scaled down so
// that it never gives more than half its largest excess (the pair would cross)
// nor goes below its floor, and a cell never takes more than half the largest
// excess it receives from nor rises above its ceiling; a cell at its ceiling
// (held down by an object) gives nothing. Mass moves from one
// cell to another in double precision, so it is conserved to double rounding.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "terrain/grid.h"

namespace drift::terrain {

// How one class of cells (a material) slides.
struct SlopeRule {
  double tan_repose = 0.577;  // tan of the steepest stable slope; +inf never slides
  double fraction = 0.2;      // sigma: share of the excess moved per pass, (0, 0.5]
};

struct SlopeRelaxOptions {
  double dx = 1.0, dy = 1.0;  // cell sizes (m)
  double tolerance = 1e-6;    // m: a pair steeper than repose by less than this is stable
  int max_passes = 200;
};

// Where each cell's rule comes from and the bounds it must keep. Null pointers
// mean: every cell follows rules[0], no ceiling, no floor.
struct SlopeCells {
  std::span<const SlopeRule> rules;
  const Grid<std::uint8_t>* rule_of_cell = nullptr;  // index into rules
  const Grid<double>* ceiling = nullptr;             // a cell never rises above it (+inf: none)
  const Grid<double>* floor = nullptr;               // a cell never sinks below it (-inf: none)
};

struct SlopeRelaxReport {
  int passes = 0;
  bool converged = false;
  double moved = 0.0;  // sum of the heights moved (m), for reports
};

// Scratch space sized to a grid, kept between calls so that a call costs what
// it touches, not the grid's size.
class SlopeRelaxWorkspace {
 public:
  void fit(std::size_t cells);

 private:
  friend struct SlopeRelaxPass;
  std::vector<std::uint32_t> seen_;  // per cell: the last epoch that listed it
  std::vector<double> in_;           // per cell: material offered to it this pass
  std::vector<double> in_excess_;    // per cell: the largest excess it is offered from
  std::uint32_t epoch_ = 0;
};

// Relaxes `heights` starting from the cells in `active` (flat indices, any order,
// duplicates allowed). On return `moved_cells` lists, unique, every cell whose
// height changed. `disturbed` (optional) accumulates |change| per cell.
SlopeRelaxReport relax_slopes(Grid<double>& heights, std::vector<int> active,
                              const SlopeCells& cells, const SlopeRelaxOptions& options,
                              std::vector<int>& moved_cells, Grid<float>* disturbed = nullptr,
                              SlopeRelaxWorkspace* workspace = nullptr);

// Largest excess of a neighbour slope over its rule, in metres of height, among
// the pairs whose higher cell is in `cells` (flat indices; empty: the whole grid)
// and whose lower cell is not capped by a ceiling (for tests and reports).
double max_slope_excess(const Grid<double>& heights, const SlopeCells& cells,
                        const SlopeRelaxOptions& options, std::span<const int> only = {});

}  // namespace drift::terrain
