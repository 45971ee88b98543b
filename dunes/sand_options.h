// The sand model's options (paper 002's parameters and the grid's) and each
// model's defaults. Their ranges live in one table, dunes/sand_parameters.h.
#pragma once

#include <cstdint>

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

}  // namespace drift::dunes
