// A shortcut for snow stabilisation's slow tail (snow/stabilise_grid.h): snow
// lying above the highest surface the repose criterion calls stable is moved at
// once to where it would come to rest, instead of creeping there by the passes.
//
// Why: the passes move at most half a pair's excess across it, so a slope that
// stands at repose and is drained at its foot (a wedge on a ledge spilling over
// the lip) or fed at its top (a pile growing in a hollow) keeps its angle and
// shifts in parallel only as fast as a diffusion: O(L^2) passes for a slope L
// cells long, each pair a fraction of a millimetre from repose. On the
// benchmark's field that is 15,000 of 17,000 passes.
//
// The shortcut, in three steps (with k = tan(repose), d the distance between
// the centres of 8-neighbours, tol the stabilisation tolerance):
//  1. the repose envelope E: the highest surface with E <= H (H = ground +
//     snow), E >= ground, and E(i) <= E(n) + k d + tol along chains of cells
//     holding snow that start at a bare neighbour n (a film thinner than tol
//     counts as bare and stays as it is). Chains start only at bare cells
//     because their surface will not rise; a deposit still filling would be
//     cut against its own low point, which is still rising. Found by a
//     label-correcting Dijkstra from the snowy cells next to bare ones;
//  2. the snow above it, H - E, runs down the steepest excess: over the cut
//     surface while it is at repose or steeper (excess >= -tol: what lay above
//     it is gone), then while it is steeper than repose by more than 10 tol and
//     the cell holds less than 100 tol of snow; it rests where it stops: at the
//     upper edge of a deposit, where the passes would stop it;
//  3. the snow resting at a cell p is heaped there as the cone of slope k over
//     the surface (Prigozhin 1994: a heap fed at a point grows as the
//     repose-limited envelope over the surface below it): H' = max(H, T -
//     k d(x, p)), d the 8-neighbour (octagonal) distance, over the connected
//     cells around p where the cone stands above H and its layer thickens
//     away from p by at most 10 tol a step; T by bisection so that the heap
//     holds exactly the snow. Where a deposit's flank stands at repose below
//     p, the cone raises it in parallel, as the passes do in many steps.
// Mass moves from cell to cell as the same doubles (to rounding); everything is
// sequential in a fixed order, so the result is the same for any thread count.
// The passes then resume and are what decides convergence: the shortcut only
// moves the snow nearer to a state they accept.
#pragma once

#include <cstddef>
#include <vector>

#include "terrain/grid.h"

namespace drift::snow {

struct SettleGeometry {
  double dx = 1.0, dy = 1.0;  // cell sizes (m)
  double tan_repose = 0.839;
  double tolerance = 1e-3;  // m: excess a pair may keep; films thinner than this stay
};

// Moves the snow above the repose envelope to where it comes to rest. Returns
// the cells whose snow changed, ascending.
std::vector<std::size_t> settle_unsupported(const terrain::Grid<float>& ground,
                                            terrain::Grid<double>& snow,
                                            const SettleGeometry& geometry);

}  // namespace drift::snow
