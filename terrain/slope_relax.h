// Slope relaxation of a height field, local and sparse: where the slope from a
// cell to one of its 8 neighbours exceeds the material's angle, material moves
// from the higher cell to the lower. One kernel for every stage that lets loose
// material slide, with the sharing rule as a parameter:
//  - SlopeShare::Fraction (paper 000, 3.5, after Sumner, O'Brien & Hodgins 1999):
//    sigma x excess to each steeper neighbour; marks' erosion (terrain/marks);
//  - SlopeShare::HalfSteepest (paper 003, 2.1(3)): a cell gives min(what it
//    holds, half its steepest excess), shared among its steeper neighbours in
//    proportion to their excess (none lower: nothing; one: all to it; several:
//    shared); snow's stabilisation (snow/stabilise_grid).
// The excess of a pair is measured against the higher cell's rule:
// e = (H_c - H_n) - tan(theta) d, d the distance between the cell centres (dx,
// dy or the diagonal); a pair counts when e > tolerance.
//
// Jacobi passes: every flow of a pass is worked out from the heights before it,
// so the result depends neither on the order of the seeds nor on the thread
// count (each cell sums what it gives and takes in a fixed neighbour order, and
// giver and taker compute each flow from the same operands, so mass moves from
// one cell to another exactly, to double rounding of the heights). A giver's
// flows are scaled so that it gives at most half its largest excess (the pair
// would cross) and never sinks below its floor; a taker takes at most half the
// largest excess it is offered from and never rises above its ceiling (offers
// counted before the givers' scaling, so the cap is conservative); a cell at its
// ceiling (held down by an object) gives nothing.
//
// Only active cells may give: the seeds at first, then every cell next to one
// that gave or took, so the work stays around the disturbance. The grid is cut
// into 16 x 16 tiles; passes visit only the tiles with active cells and their
// neighbours, in parallel (TBB) when there are many (relax_slopes_everywhere);
// relax_slopes keeps lists of the active cells instead and visits only them
// and their neighbours (paper 000, 3.5: only where needed), with the same
// flows and bits: both loops run the same pass. A pass works out each giver's
// eight excesses once and keeps them (ten doubles a giver), so takers and
// flows read them instead of evaluating each pair three times. Storage: a double,
// a slot index, a list stamp and three flag bytes a cell in the workspace (19
// bytes), none per flow.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include "terrain/grid.h"

namespace drift::terrain {

enum class SlopeShare {
  Fraction,      // paper 000: fraction x excess to each steeper neighbour
  HalfSteepest,  // paper 003: min(held, e_max / 2) shared in proportion to excess
};

// How one class of cells (a material) slides.
struct SlopeRule {
  double tan_repose = 0.577;  // tan of the steepest stable slope; +inf never slides
  double fraction = 0.2;      // sigma (SlopeShare::Fraction): share of the excess a pass, (0, 0.5]
  SlopeShare share = SlopeShare::Fraction;
  // Roughness (paper 000, 3.5: sigma "sets the roughness of the slumped slope,
  // smaller being smoother"; Sumner et al. 1999). Each cell slides at its own
  // angle, tan_repose (1 - fraction u), u uniform in [0, 1) drawn from the
  // options' seed and the cell (terrain/hash.h: any thread count, the same
  // angle in every call), so slumped slopes stand between (1 - sigma) and 1
  // times tan theta, never steeper: a small sigma gives a smooth slope, a large
  // one a lumpy, grainy one. The share moved a pass stays sigma x excess.
  bool rough = false;
};

struct SlopeRelaxOptions {
  double dx = 1.0, dy = 1.0;  // cell sizes (m)
  double tolerance = 1e-6;    // m: a pair steeper than repose by less than this is stable
  int max_passes = 200;
  std::uint64_t seed = 0;  // for rules with `rough`: which cells stand steeper
  // m: a cell whose height changes by no more than this in a pass (net of
  // what it gives and takes) does not keep its neighbours active in the next
  // (relax_slopes only; 0: any flow does). A region whose cells all move less
  // has settled and drops out of the passes, while a bow wave still moving
  // keeps its own cells going.
  double settle = 0.0;
  // The roughness draws' cell (SlopeRule::rough) when the grid is a window of
  // a larger raster (marks run block by block): the window's cell (x, y)
  // draws as the raster's cell (index_x0 + x, index_y0 + y) of a raster
  // index_width cells wide does, so a block's window slides as the whole
  // raster would. 0: the grid's own flat index.
  std::int64_t index_width = 0;
  int index_x0 = 0, index_y0 = 0;
};

// Called after each pass with the passes so far and the share of the tiles still
// active (for progress bars; it may throw to cancel).
using SlopePassFn = std::function<void(int passes, double active_share)>;

// Where each cell's rule comes from and the bounds it must keep. Null pointers
// mean: every cell follows rules[0], no ceiling, no floor.
struct SlopeCells {
  std::span<const SlopeRule> rules;
  const Grid<std::uint8_t>* rule_of_cell = nullptr;  // index into rules
  const Grid<double>* ceiling = nullptr;             // a cell never rises above it (+inf: none)
  const Grid<double>* floor = nullptr;               // a cell never sinks below it (-inf: none)
  // The relaxed field may be a loose layer on a fixed base (snow depth on the
  // ground): slopes are those of base + field, bounds apply to the field.
  const Grid<float>* base = nullptr;
  double min_value = -std::numeric_limits<double>::infinity();  // a floor for every cell
};

struct SlopeRelaxReport {
  int passes = 0;
  bool converged = false;
  double moved = 0.0;  // sum of the heights moved (m), for reports
};

// Scratch space sized to a grid, kept between calls so that a call costs what
// it touches, not the grid's size (its flags are back to zero between calls).
class SlopeRelaxWorkspace {
 public:
  void fit(int width, int height);

 private:
  friend class SlopeRelaxer;
  int width_ = 0, height_ = 0, tiles_x_ = 0, tiles_y_ = 0;
  std::vector<double> take_;  // per taker: the share of its offers it takes this pass
  std::vector<int> slot_;     // per cell: its place in this pass's givers from 1, 0: not giving
  // Per giver of a pass: its eight excesses, its factor (0: gives nothing),
  // its offers' factor and its flows'.
  std::vector<double> excess_, factor_, mult_, post_;
  std::vector<std::uint8_t> offers_;                   // per giver: it gives this pass (factor > 0)
  std::vector<std::uint8_t> active_, touched_, ever_;  // per cell
  // Cell lists as a bitmap (a bit a cell, zero between uses) and, per row, the
  // words in use (lo > hi: none).
  int words_ = 0;  // per row
  std::vector<std::uint64_t> bits_;
  std::vector<int> row_lo_, row_hi_;
  std::vector<std::uint8_t> tile_active_, tile_touched_, tile_ever_, tile_mark_;
};

// Relaxes `heights` starting from the cells in `active` (flat indices, any order,
// duplicates allowed). On return `moved_cells` lists, unique and in ascending
// order, every cell that gave or took. `disturbed` (optional) accumulates the
// material moved in and out per cell.
SlopeRelaxReport relax_slopes(Grid<double>& heights, const std::vector<int>& active,
                              const SlopeCells& cells, const SlopeRelaxOptions& options,
                              std::vector<int>& moved_cells, Grid<float>* disturbed = nullptr,
                              SlopeRelaxWorkspace* workspace = nullptr);

// The same with every cell active at first (a whole field to settle).
SlopeRelaxReport relax_slopes_everywhere(Grid<double>& heights, const SlopeCells& cells,
                                         const SlopeRelaxOptions& options,
                                         SlopeRelaxWorkspace* workspace = nullptr,
                                         const SlopePassFn& on_pass = {});

// Largest excess of a neighbour slope over its rule, in metres of height, among
// against the rule's tan_repose (not a rough cell's own, which is lower),
// the pairs whose higher cell is in `cells` (flat indices; empty: the whole grid)
// and holds more than `min_room` above its floor, and whose lower cell is not
// capped by a ceiling (for tests and reports).
double max_slope_excess(const Grid<double>& heights, const SlopeCells& cells,
                        const SlopeRelaxOptions& options, std::span<const int> only = {},
                        double min_room = -std::numeric_limits<double>::infinity());

}  // namespace drift::terrain
