// Avalanching of dry granular material on a periodic height field: sand moves
// downhill across every cell edge steeper than the angle of repose until none
// is (beyond paper 002, so that slip faces form: docs/dunes.md, The model, 3).
#pragma once

#include <vector>

#include "terrain/grid.h"

namespace drift::dunes {

// `max_drop` is the largest height difference allowed between edge
// neighbours, in the field's height unit (tan(repose) * cell / height unit).
// Edges join the 8 neighbours (diagonals sqrt(2) cells long, so the slope in
// any direction is limited, within 8 %, not only its east and north parts).
// Each sweep moves, across every edge steeper than its limit, a ninth of the
// excess (so that no cell, with at most 8 downhill edges, overshoots);
// sweeps are Jacobi updates of antisymmetric edge fluxes, so mass is
// conserved and the result is the same for any thread count. Stops when no
// edge exceeds max_drop by more than `tolerance` (checked every 8 sweeps) or
// after `max_sweeps`; returns the sweeps done. A negative tolerance skips the
// checks (all `max_sweeps` run).
//
// `shift`: h is a wind lattice (dunes/wind_frame.h) whose row 0 goes on past
// its last row `shift` columns back; 0 for a plain periodic grid. Edges are
// those of a square lattice of the field's own spacing (the caller scales
// max_drop to it).
int avalanche(terrain::HeightField& h, double max_drop, int max_sweeps, double tolerance = 1e-4,
              int shift = 0);
// The same with caller-owned scratch for the new field (kept between calls,
// so a run does not allocate and clear it every step).
int avalanche(terrain::HeightField& h, double max_drop, int max_sweeps, double tolerance,
              std::vector<float>& scratch, int shift = 0);

// How far the steepest edge (of 8 neighbours) exceeds its limit (<= 0: none).
double max_excess(const terrain::HeightField& h, double max_drop, int shift = 0);

}  // namespace drift::dunes
