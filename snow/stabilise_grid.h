// Stabilisation of fallen snow on a height field (paper 003, 2.1(3), 2.2(3)):
// each cell compares its snow surface (ground + snow) with its 4 neighbours:
//   (1) no neighbour lower: nothing moves;
//   (2) one neighbour lower: snow moves to it;
//   (3) two or more lower: the snow is shared among them, in proportion to how
//       much lower each is.
// The paper does not say how much moves. Here (SPEC 3a) a neighbour counts as
// lower only where the snow surface slope to it exceeds the angle of repose, by
// the excess e = (H_i - H_j) - tan(repose) * L; the cell gives
// min(snow held, relaxation x e_max / 2) (half the steepest excess brings that pair
// exactly to repose), so a cell never gives more snow than it holds and bare
// ground never moves. Repeated until nothing moves by more than `tolerance`.
//
// Cells give in red-black order (Gauss-Seidel, parallel within a colour) from the
// state before the pass, each flow leaving one cell and entering another in double
// precision, so the result does not depend on
// the thread count and mass is conserved to double rounding; the grid's edges are
// closed (no flow out). Tiles where nothing moved sleep until a neighbour moves.
#pragma once

#include "terrain/grid.h"
#include "terrain/progress.h"

namespace drift::snow {

struct StabiliseOptions {
  double repose_deg = 40.0;  // angle of repose of snow, (0, 90)
  double tolerance = 1e-6;   // m: converged when no cell gives more than this in a pass
  int max_iterations = 100000;
  // Over-relaxation of each transfer (as in SOR), [1, 1.95]: the snow surface relaxes
  // like a diffusion, which plain passes settle in O(size^2) passes; 1.9 settles the
  // Yarigatake test case in 288 passes instead of 2366, to the same tolerance.
  double relaxation = 1.9;
};

struct StabiliseReport {
  int iterations = 0;
  bool converged = false;
};

// ground: heights (m); snow: depth (m, vertical), updated in place. dx, dy: cell sizes (m).
StabiliseReport stabilise_grid(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                               double dx, double dy, const StabiliseOptions& options = {},
                               const ProgressFn& progress = no_progress);

// Largest excess of the snow-surface slope over the angle of repose, in metres of
// height, over every pair of 4-neighbours where the higher one holds more than
// `min_snow` of snow (for tests and reports).
double max_repose_excess(const terrain::Grid<float>& ground, const terrain::Grid<double>& snow,
                         double dx, double dy, double repose_deg, double min_snow);

}  // namespace drift::snow
