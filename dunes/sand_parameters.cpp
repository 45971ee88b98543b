#include "dunes/sand_parameters.h"

#include <cstring>

namespace drift::dunes {

using terrain::Ends;

const std::vector<terrain::Parameter<SandOptions>>& sand_parameters() {
  static const std::vector<terrain::Parameter<SandOptions>> table = {
      {"size", "--size", 8, 16384, Ends::Closed, true, "cells",
       "cells per side of the periodic square grid (any size, not only powers of two)",
       DRIFT_PARAMETER_FIELD(SandOptions, size)},
      {"cell_m", "--cell", 1e-4, 1e3, Ends::Closed, false, "m", "cell size",
       DRIFT_PARAMETER_FIELD(SandOptions, cell_m)},
      {"height_unit", "--height-unit", 1e-6, 1e3, Ends::Closed, false, "m",
       "metres per model height unit: sets the physical slopes",
       DRIFT_PARAMETER_FIELD(SandOptions, height_unit)},
      {"steps", "--steps", 0, 1e7, Ends::Closed, true, "", "time steps; 0 writes the seeded start",
       DRIFT_PARAMETER_FIELD(SandOptions, steps)},
      {"wind_from_deg", "--wind", -360, 360, Ends::Closed, false, "degrees",
       "where the wind comes FROM, clockwise from north (270: a west wind)",
       DRIFT_PARAMETER_FIELD(SandOptions, wind_from_deg)},
      {"L0", "--L0", 0.5, 64, Ends::Closed, false, "cells",
       "base flight length; ripples come out ~1.3-1.8 L0 long",
       DRIFT_PARAMETER_FIELD(SandOptions, L0)},
      {"b", "--b", 0, 32, Ends::Closed, false, "", "flight-length coefficient (dunes: below L0)",
       DRIFT_PARAMETER_FIELD(SandOptions, b)},
      {"q", "--q", 1e-4, 2, Ends::Closed, false, "height units",
       "height lifted per cell and step (dunes: q0)", DRIFT_PARAMETER_FIELD(SandOptions, q)},
      {"b_prime", "--b-prime", 0, 2, Ends::Closed, false, "height units",
       "extra lift on windward slopes (below q)", DRIFT_PARAMETER_FIELD(SandOptions, b_prime)},
      {"creep", "--creep", 0, 1, Ends::Closed, false, "", "creep (diffusion) coefficient D",
       DRIFT_PARAMETER_FIELD(SandOptions, creep)},
      {"initial_amplitude", "--amplitude", 0, 1e3, Ends::Closed, false, "height units",
       "random start amplitude", DRIFT_PARAMETER_FIELD(SandOptions, initial_amplitude)},
      {"repose_deg", "--repose", 1, 89, Ends::Closed, false, "degrees",
       "angle of repose of dry sand", DRIFT_PARAMETER_FIELD(SandOptions, repose_deg)},
      {"shadow_deg", "--shadow", 0, 89, Ends::Closed, false, "degrees",
       "wind-shadow angle behind crests (0: none)", DRIFT_PARAMETER_FIELD(SandOptions, shadow_deg)},
      {"reattach", "--reattach", 0, 16, Ends::Closed, false, "shadow lengths",
       "with a shadow: the lift past it recovers over this many times its length (0: at once)",
       DRIFT_PARAMETER_FIELD(SandOptions, reattach)},
  };
  return table;
}

bool dunes_only(const terrain::Parameter<SandOptions>& p) {
  return std::strcmp(p.field, "b_prime") == 0;
}

}  // namespace drift::dunes
