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

#include "dunes/wind_shadow.h"
#include "terrain/grid.h"
#include "terrain/progress.h"

namespace drift::dunes {

enum class Model {
  Ripples,  // L = L0 + b H,            q constant                (paper eq. 1)
  Dunes,    // L = L0 - b tanh(dH/dx),  q = q0 + b' tanh(dH/dx)   (paper eqs. 2-3)
};

struct SandOptions {
  Model model = Model::Ripples;
  int size = 256;               // cells per side of the periodic square grid, [8, 16384]
  double cell_m = 0.015;        // metres per cell (ripples 1-2 cm, dunes 0.5-2 m)
  double height_unit = 0.0025;  // metres per model height unit
  int steps = 500;              // time steps: saltation, creep, avalanching
  std::uint64_t seed = 1;
  double wind_from_deg = 270.0;    // where the wind comes FROM, clockwise from north
  double L0 = 5.0;                 // base flight length, cells
  double b = 2.0;                  // ripples: cells per height unit; dunes: tanh coefficient
  double q = 0.1;                  // height units lifted per cell and step (dunes: q0)
  double b_prime = 0.0;            // dunes: extra lift on windward slopes
  double creep = 0.25;             // D in H += D * (mean of 4 neighbours - H) * 4 / 4
  double initial_amplitude = 1.0;  // random start: uniform in [0, amplitude) height units
  double repose_deg = 34.0;        // angle of repose of dry sand
  // The lee of a crest below this angle is out of the wind (Werner 1995;
  // beyond paper 002, which has no wind shadow): no lift there, and grains
  // flying into it are caught. Dunes 15. Ripples 0 by default: a shadow of
  // 5-8 degrees (grains arrive at shallow angles and miss ripple lee faces,
  // Anderson 1987) makes them migrate downwind, but their crests come out
  // shorter and less regular than without. 0 turns it off.
  double shadow_deg = 0.0;
  // With a shadow: past its end the lift rises linearly from 0 to full over
  // this many times the shadow's length (the flow reattaching and the flux
  // saturating; see shadow_recovery()). Dunes 1: gentle windward faces and
  // crescent slip faces; 2 and more: separate crescents (barchanoid dunes);
  // 0: the full lift at once, which scours pits with steep windward walls.
  double reattach = 0.0;
};

// The defaults of each model (documented in `drift dunes --help`).
SandOptions default_options(Model model);

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
