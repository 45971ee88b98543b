// Avalanching of dry granular material on a periodic height field: sand moves
// downhill across every cell edge steeper than the angle of repose until none
// is (beyond paper 002, required by SPEC 2 so that slip faces form).
#pragma once

#include "terrain/grid.h"

namespace drift::dunes {

// `max_drop` is the largest height difference allowed between edge
// neighbours, in the field's height unit (tan(repose) * cell / height unit).
// Each sweep moves, across every edge steeper than that, a fifth of the excess
// (so that no cell, with at most 4 downhill edges, overshoots its neighbours);
// sweeps are Jacobi updates of antisymmetric edge fluxes, so mass is
// conserved and the result is the same for any thread count. Stops when no
// edge exceeds max_drop by more than `tolerance` (checked every 8 sweeps) or
// after `max_sweeps`; returns the sweeps done.
int avalanche(terrain::HeightField& h, double max_drop, int max_sweeps, double tolerance = 1e-4);

// The steepest edge drop of the field (periodic), in its height unit.
double max_edge_drop(const terrain::HeightField& h);

}  // namespace drift::dunes
