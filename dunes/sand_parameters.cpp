#include "dunes/sand_parameters.h"

#include "terrain/parameter.h"

namespace drift::dunes {

namespace {

// A row's accessors for SandOptions member `m` (int, double or uint64).
#define DRIFT_SAND_FIELD(m)                                      \
  [](const SandOptions& o) { return static_cast<double>(o.m); }, \
      [](SandOptions& o, double v) { o.m = static_cast<decltype(o.m)>(v); }

}  // namespace

const std::vector<SandParameter>& sand_parameters() {
  static const std::vector<SandParameter> table = {
      {"size", "--size", 8, 16384, true, false, "cells",
       "cells per side of the periodic square grid (any size, not only powers of two)",
       DRIFT_SAND_FIELD(size)},
      {"cell_m", "--cell", 1e-4, 1e3, false, false, "m", "cell size", DRIFT_SAND_FIELD(cell_m)},
      {"height_unit", "--height-unit", 1e-6, 1e3, false, false, "m",
       "metres per model height unit: sets the physical slopes", DRIFT_SAND_FIELD(height_unit)},
      {"steps", "--steps", 0, 1e7, true, false, "", "time steps; 0 writes the seeded start",
       DRIFT_SAND_FIELD(steps)},
      {"wind_from_deg", "--wind", -360, 360, false, false, "degrees",
       "where the wind comes FROM, clockwise from north (270: a west wind)",
       DRIFT_SAND_FIELD(wind_from_deg)},
      {"L0", "--L0", 0.5, 64, false, false, "cells",
       "base flight length; ripples come out ~1.3-1.8 L0 long", DRIFT_SAND_FIELD(L0)},
      {"b", "--b", 0, 32, false, false, "", "flight-length coefficient (dunes: below L0)",
       DRIFT_SAND_FIELD(b)},
      {"q", "--q", 1e-4, 2, false, false, "height units",
       "height lifted per cell and step (dunes: q0)", DRIFT_SAND_FIELD(q)},
      {"b_prime", "--b-prime", 0, 2, false, true, "height units",
       "extra lift on windward slopes (below q)", DRIFT_SAND_FIELD(b_prime)},
      {"creep", "--creep", 0, 1, false, false, "", "creep (diffusion) coefficient D",
       DRIFT_SAND_FIELD(creep)},
      {"initial_amplitude", "--amplitude", 0, 1e3, false, false, "height units",
       "random start amplitude", DRIFT_SAND_FIELD(initial_amplitude)},
      {"repose_deg", "--repose", 1, 89, false, false, "degrees", "angle of repose of dry sand",
       DRIFT_SAND_FIELD(repose_deg)},
      {"shadow_deg", "--shadow", 0, 89, false, false, "degrees",
       "wind-shadow angle behind crests (0: none)", DRIFT_SAND_FIELD(shadow_deg)},
      {"reattach", "--reattach", 0, 16, false, false, "shadow lengths",
       "with a shadow: the lift past it recovers over this many times its length (0: at once)",
       DRIFT_SAND_FIELD(reattach)},
  };
  return table;
}

#undef DRIFT_SAND_FIELD

std::string range_text(const SandParameter& p) {
  return terrain::range_text(p.lo, p.hi, terrain::Ends::Closed, p.unit);
}

}  // namespace drift::dunes
