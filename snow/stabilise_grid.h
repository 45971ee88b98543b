// Stabilisation of fallen snow on a height field (paper 003, 2.1(3), 2.2(3)):
// each cell compares its snow surface (ground + snow) with its neighbours:
//   (1) no neighbour lower: nothing moves;
//   (2) one neighbour lower: snow moves to it;
//   (3) two or more lower: the snow is shared among them, in proportion to how
//       much lower each is.
// The paper does not say how much moves. Here (SPEC 3a) a neighbour counts as
// lower only where the snow surface slope to it exceeds the angle of repose, by
// the excess e = (H_i - H_j) - tan(repose) * L, L the distance between the cell
// centres; the cell gives min(snow held, e_max / 2) (half the steepest excess
// brings that pair exactly to repose, never past it), so a cell never gives more
// snow than it holds and bare ground never moves.
//
// Departure from the paper: 8 neighbours (the diagonals at their distance), not
// the paper's 4, which let diagonal slopes stand at up to 50 degrees when the
// repose angle is 40. A settled pile is then an octagonal cone whose flanks
// along the 8 grid directions stand at the repose angle; between them its faces
// are up to atan(1.082 tan(repose)) steep (42.2 degrees for 40).
//
// No over-relaxation: moving more than half the excess throws snow past the
// point where the pair is at repose, and what was thrown never comes back, so
// piles would end flatter than the repose angle. The converged state depends
// only on the rule above.
//
// Order: the cells are coloured by (x mod 2, y mod 2), so no two cells of one
// colour are neighbours; the colours give in turn (a pass = four turns). In a
// turn the givers work out their shares from the state before the turn
// (parallel, independent of the thread count and of the order of the cells),
// then every receiver adds what it gets, then the givers subtract what they
// gave: each transfer leaves one cell and enters another as the same double, so
// mass is conserved to double rounding. The grid's edges are closed (no flow
// out). Tiles where nothing moved sleep until a neighbour moves; the run ends
// with a pass over every tile that moves nothing.
#pragma once

#include "terrain/grid.h"
#include "terrain/progress.h"

namespace drift::snow {

struct StabiliseOptions {
  double repose_deg = 40.0;  // angle of repose of snow, (0, 90)
  double tolerance = 1e-6;   // m: converged when no cell gives more than this in a pass
  int max_iterations = 100000;
};

struct StabiliseReport {
  int iterations = 0;  // passes: every cell has had its turn once per pass
  bool converged = false;
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
