// Snow stabilisation in one step (issue 36, item 3): the state at rest computed
// directly instead of by passes, at a cost near linear in the area
// (O(N log N) a layer: one Dijkstra, one pass down over the cells the loose
// snow crosses, highest first, and one priority flood over each heap's cells), with the mass exact
// to rounding and no pair of 8-neighbours steeper than the angle of repose where the higher holds
// snow.
//
// The passes (snow/stabilise_grid.h) shift a slope standing at repose only as
// fast as a diffusion (O(L^2) passes for a slope L cells long); this solver
// instead builds the state at rest from two surfaces that each stand at rest:
//  1. the drained surface E: the highest surface under today's (H = ground +
//     snow) at rest, E(i) = min(H(i), max(ground(i), min_n E(n) + k d)), k =
//     tan(repose), d the distance to the 8-neighbour n (the greatest fixed
//     point, by Dijkstra from the lowest labels; each is final when popped).
//     Snow on ground steeper than repose is cut down to what the snow below
//     it holds up; snow at rest is not touched;
//  2. the snow cut off, H - E, runs down to every neighbour the surface falls
//     to more steeply than repose, shared in proportion to the excess (the
//     passes' rule, paper 003 2.1(3); strictly down, so no loops; over cut
//     cells also down the cut at repose), and stops where nothing is
//     steeper: where the passes would stop it (a column's cut snow stays on
//     the column);
//  3. there it is heaped as the cone of slope k (Prigozhin 1994; Prigozhin 1996: a heap
//     fed at a point grows as the repose-limited surface over what lies below
//     it) over the connected cells where the cone stands above the surface,
//     its apex found exactly by one priority flood (heap_at); where the cone
//     would reach over a pass onto lower ground, it is heaped up to the pass
//     and the rest spills on.
// Why the result stands at rest: E does (its definition), a cone does (its
// slope is k along every 8-neighbour step, the same metric), and the maximum
// of two surfaces at rest over the same ground is at rest, taken over the
// cone's connected region (its neighbours outside are at least as high as the
// cone). So the state is at rest by construction, in every direction, up to
// 1e-7 m (what a heap may step over a pass), not up to the passes' 1 mm.
//
// It is a different path to rest, so not the passes' state: the snow is
// heaped where it first stops instead of creeping on while the deposits
// grow (settling it in layers brings it closer). docs/snowfall.md gives
// the distance to the passes' state measured on the benchmark field.
// Everything runs in a fixed order on one thread: the same bits for any
// thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "terrain/grid.h"

namespace drift::snow {

struct DirectReport {
  std::size_t cut_cells = 0;  // cells the drained surface cut
  std::size_t heaps = 0;      // cells where cut snow came to rest
  std::size_t spills = 0;     // heaps that filled up to a pass and spilled over it
  double loose = 0.0;         // m of snow x cells moved
};

// ground: heights (m); snow: depth (m), updated in place; dx, dy: cell sizes
// (m); tan_repose = tan(angle of repose). layers > 1: the snow settled in that
// many equal layers, each added to the state at rest of those before it and
// settled in turn (the snow falls over hours): the deposit a slope's snow
// gathers into then rises under it and holds its lower snow up, as the
// passes' deposits do, and each heap is small, so the order heaps are built
// in matters less. Cost x layers; docs/snowfall.md gives the distance to the
// passes' state against the number of layers.
//
// touched (optional): set to 1 at every cell the run cut, routed snow
// through or heaped onto (the cells whose snow it may have changed, and those
// snow passed over on its way); sized to the grid if it is not. The block by
// block run (snow/snowfall_blocks.h) reads it to know how far a window's
// snow moved.
DirectReport settle_at_rest(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                            double dx, double dy, double tan_repose, int layers = 1,
                            std::vector<std::uint8_t>* touched = nullptr);

}  // namespace drift::snow
