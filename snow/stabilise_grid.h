// Stabilisation of fallen snow on a height field (paper 003, 2.1(3), 2.2(3)):
// each cell compares its snow surface (ground + snow) with its neighbours:
//   (1) no neighbour lower: nothing moves;
//   (2) one neighbour lower: snow moves to it;
//   (3) two or more lower: the snow is shared among them, in proportion to how
//       much lower each is.
// The paper does not say how much moves. Here (docs/snowfall.md, Stabilisation)
// a neighbour counts as lower only where the snow surface slope to it exceeds
// the angle of repose, by the excess e = (H_i - H_j) - tan(repose) * L, L the
// distance between the cell centres; the cell gives min(snow held, e_max / 2)
// (half the steepest excess brings that pair exactly to repose, never past it),
// so a cell never gives more snow than it holds and bare ground never moves. No
// over-relaxation: snow thrown past the point where a pair is at repose never
// comes back, so piles would end flatter than the repose angle.
//
// Departure from the paper: 8 neighbours (the diagonals at their distance), not
// the paper's 4, which let diagonal slopes stand at up to 50 degrees when the
// repose angle is 40. A settled pile is an octagonal cone whose flanks along the
// 8 grid directions stand at the repose angle.
//
// The passes are terrain/slope_relax's SlopeShare::HalfSteepest passes (shared
// with marks' erosion), specialised here to snow on ground and written for
// speed (the surface kept as one array, inner cells without edge tests): the
// same operations in the same order, so the same bits (a test holds them to
// it). Jacobi passes over the cells next to whatever moved, each flow leaving
// one cell and entering another as the same double, so mass is conserved to
// double rounding and the result does not depend on the thread count; the
// grid's edges are closed (no flow out). Only the cells next to whatever moved
// in the last pass are looked at, so the cost of a pass follows the snow that
// is still moving, not the grid.
//
// Why a field takes many passes (docs/snowfall.md): a pass moves at most half a
// pair's excess across it, so a slope standing at repose that is drained at its
// foot or fed at its top shifts in parallel only as fast as a diffusion, in
// O(L^2) passes for a slope L cells long. Once the passes are in that slow tail
// (fewer than 10 % of the tiles active, 200 passes after the last time), the
// repose-envelope shortcut (snow/stabilise_settle.h) moves the unsupported snow
// to where it comes to rest; the passes then resume and decide convergence, so
// the criterion is the same. The settled state is near, not equal, to the
// passes' own (benchmark field: RMS 0.8 cm at 1024^2; StabiliseOptions::shortcut
// = false gives the passes alone). An optional coarse-to-fine start
// (StabiliseOptions::coarse_levels, snow/stabilise_levels.h) settles the field
// on 2 x 2 blocks first; the passes on the grid still decide convergence.
#pragma once

#include <cstdint>
#include <vector>

#include "terrain/grid.h"
#include "terrain/progress.h"

namespace drift::snow {

struct StabiliseOptions {
  double repose_deg = 40.0;  // angle of repose of snow, (0, 90)
  // m: a pair steeper than repose by less than this, or a film thinner than this,
  // is stable (1 mm: 0.04 degrees on 1 m cells, far below what a render shows).
  double tolerance = 1e-3;
  int max_iterations = 100000;
  // The repose-envelope shortcut for the passes' slow tail
  // (snow/stabilise_settle.h); false: the passes alone.
  bool shortcut = true;
  // The coarse-to-fine start (snow/stabilise_levels.h): the field settled
  // first on this many levels of 2 x 2 blocks (fewer where a level would be
  // smaller than 32 cells a side); 0: the passes on the grid alone. Faster
  // (benchmark field, one level: 2.4 x at 1024^2 and 4096^2) with piles at
  // repose as the passes leave them, but not the default: the state is a few
  // cm from the passes' own (one level: RMS 2.3 cm at 1024^2), see
  // docs/snowfall.md.
  int coarse_levels = 0;
  // The state at rest in one step (snow/stabilise_direct.h) instead of the
  // passes: near-linear cost, mass exact, at rest in every direction by
  // construction, a different path to rest (docs/snowfall.md gives its
  // distance to the passes' state). max_iterations, shortcut, coarse_levels
  // and tolerance's pass criterion do not apply; tolerance still decides the
  // report's `converged` (no pair steeper than repose by more than it).
  bool direct = false;
  // With direct: the snow settled in this many equal layers, each on the
  // state at rest of those before (settle_at_rest); closer to the passes'
  // state the more layers, at their cost (docs/snowfall.md).
  int direct_layers = 4;
  // Bytes a cell the caller holds beside the workspace (snowfall: the ground,
  // probability, facing and snow grids), counted in its memory checks.
  std::uint64_t held_bytes_per_cell = 0;
};

struct StabiliseReport {
  int iterations = 0;  // passes (each cell next to a move looked at once a pass)
  bool converged = false;
  // Passes of each level, coarsest first, this grid's last (= iterations).
  std::vector<int> level_passes;
};

// ground: heights (m); snow: depth (m, vertical), updated in place. dx, dy: cell sizes (m).
StabiliseReport stabilise_grid(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                               double dx, double dy, const StabiliseOptions& options = {},
                               const ProgressFn& progress = no_progress);

// Largest excess of the snow-surface slope over the angle of repose, in metres of
// height, over every pair of 8-neighbours (diagonals at their distance) where the
// higher one holds more than `min_snow` of snow (for tests and reports).
double max_repose_excess(const terrain::Grid<float>& ground, const terrain::Grid<double>& snow,
                         double dx, double dy, double repose_deg, double min_snow);

}  // namespace drift::snow
