// Nishimori-Ouchi sand transport on a periodic height field (paper 002, sec. 2,
// after Nishimori & Ouchi 1993, PRL 71:197): wind ripples and dunes from
// saltation and creep, plus avalanching to the angle of repose (beyond the
// paper; docs/dunes.md, The model, 3).
//
// Frames and units. The model runs in the wind's frame (dunes/wind_frame.h):
// the ground grid turned by whole quarter turns so that the wind blows within
// 45 degrees of +x (columns), along (cos a, sin a). The sand lives on the wind
// lattice, a square lattice turned to the wind whose rows are the wind
// lines, periodic with the grid: every azimuth gives a tileable field.
// Flight lengths are in grid cells and heights in the model's dimensionless
// unit, as in the paper; one model unit is `height_unit` metres and one cell
// `cell_m` metres, which fixes the physical slopes that avalanching limits.
// run() returns the field on the model grid; to_ground() turns it back by the
// quarter turns and into metres.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "dunes/sand_options.h"
#include "dunes/wind_shadow.h"
#include "terrain/grid.h"
#include "terrain/progress.h"

namespace drift::dunes {

// Throws drift::Error naming the option, its value and its range.
void validate(const SandOptions& options);

// The seeded random start on the wind lattice of wind_lattice(wind, size)
// (model units).
terrain::HeightField initial_field(const SandOptions& options);

// Scratch memory of a run, kept from step to step (allocating it every step
// costs page faults and clearing).
struct Workspace {
  ShadowMap shadow;         // the wind shadow
  std::vector<float> next;  // the new field (saltation, creep, avalanching)
  // Steps done, and whether the last step's avalanching found steep edges:
  // while slip faces keep forming, the per-step check (a full pass) is
  // skipped but every 8th step.
  long long steps = 0;
  bool steep = true;
};

// The functions below take `h` on the wind lattice of wind_lattice(wind,
// options.size) (for a wind along the grid's axes, the grid itself).
//
// Saltation along the wind (paper eq. 1 or eqs. 2-3): every point lifts q
// and drops it L cells downwind on its wind line, L / s columns on (s: the lattice spacing,
// dunes/wind_frame.h); a landing between points is shared linearly between the 2 around it, as the
// paper has it. Summed in double precision in a fixed order: exact mass
// bookkeeping and the same bits for any thread count.
void saltate(terrain::HeightField& h, const SandOptions& options, Workspace& workspace);
void saltate(terrain::HeightField& h, const SandOptions& options);

// Creep: H += D/4 * (sum of the 4 neighbours - 4 H) (the paper's diffusion),
// as antisymmetric fluxes across edges, so mass is conserved. `shift`: the
// wind lattice's (dunes/lattice.h); the coefficient per lattice spacing
// (D / s^2 for the paper's D per cell).
void creep(terrain::HeightField& h, double coefficient, Workspace& workspace, int shift = 0);
void creep(terrain::HeightField& h, double coefficient, int shift = 0);

// One time step: saltate, creep, then a few avalanche relaxation sweeps.
void step(terrain::HeightField& h, const SandOptions& options, Workspace& workspace);
void step(terrain::HeightField& h, const SandOptions& options);

// The whole run in the wind's frame, in model units (for tests and snapshots):
// on the wind lattice, then on the model grid (lattice_to_grid()) relaxed to
// the angle of repose. `snapshot(k, field)` is called after every
// `snapshot_every` steps if > 0, with the field on the model grid.
using SnapshotFn = std::function<void(int step, const terrain::HeightField& model_field)>;
terrain::HeightField run(const SandOptions& options, const ProgressFn& progress = no_progress,
                         int snapshot_every = 0, const SnapshotFn& snapshot = nullptr);

// Model field (wind frame, model units) -> ground field: turned by the wind
// frame's quarter turns (exact, tileable) and in metres with a local
// georeference of cell_m.
terrain::HeightField to_ground(const terrain::HeightField& model_field, const SandOptions& options);

// run() then to_ground().
terrain::HeightField simulate(const SandOptions& options, const ProgressFn& progress = no_progress);

}  // namespace drift::dunes
