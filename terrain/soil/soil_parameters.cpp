#include "terrain/soil/soil_parameters.h"

namespace drift::soil {

using terrain::Ends;

const std::vector<SoilParameter>& soil_parameters() {
  static const std::vector<SoilParameter> table = {
      // The soil (the thesis's table 6); a preset (`type`, --soil) sets all four.
      {"soil.phi_deg", "--phi", 0, 60, Ends::OpenHigh, false, "degrees",
       "angle of internal friction phi, over the scenario's soil",
       DRIFT_PARAMETER_FIELD(SoilOptions, soil.phi_deg), "[soil] phi"},
      {"soil.cohesion", "--cohesion", 0, 20, Ends::Closed, false, "t/m",
       "cohesion c, over the scenario's soil", DRIFT_PARAMETER_FIELD(SoilOptions, soil.cohesion),
       "[soil] cohesion"},
      {"soil.gamma", "--gamma", 0, 10, Ends::OpenLow, false, "t/m^2",
       "specific weight gamma, over the scenario's soil",
       DRIFT_PARAMETER_FIELD(SoilOptions, soil.gamma), "[soil] gamma"},
      {"soil.moisture", "--moisture", 0, 1, Ends::Closed, false, "",
       "moisture (0 dry .. 1 damp) the soil starts with where a soil body gives none: "
       "adds cohesion, wets the surface",
       DRIFT_PARAMETER_FIELD(SoilOptions, soil.moisture), "[soil] moisture"},
      {"soil.drainage", "--drainage", 0, 1, Ends::Closed, false, "m/s",
       "saturated hydraulic conductivity K_s: water drains down the soil at K_s S^(2b+3)",
       DRIFT_PARAMETER_FIELD(SoilOptions, soil.drainage), "[soil] drainage"},
      {"soil.evaporation", "--evaporation", 0, 1e-3, Ends::Closed, false, "m/s",
       "evaporation of water from the soil's exposed top",
       DRIFT_PARAMETER_FIELD(SoilOptions, soil.evaporation), "[soil] evaporation"},
      // The time stepping (section 4.2 of the thesis).
      {"dt", "", 0, 1, Ends::OpenLow, false, "s", "time step (soil moves at most a voxel a step)",
       DRIFT_PARAMETER_FIELD(SoilOptions, dt), "[simulation] dt"},
      {"gravity", "", 0, 100, Ends::Closed, false, "m/s^2", "gravity",
       DRIFT_PARAMETER_FIELD(SoilOptions, gravity), "[simulation] gravity"},
      {"propagation_iterations", "", 0, 64, Ends::Closed, true, "",
       "the thesis's alpha: passes that carry a body's push through the soil",
       DRIFT_PARAMETER_FIELD(SoilOptions, propagation_iterations),
       "[simulation] propagation_iterations"},
      {"overflow_passes", "", 0, 64, Ends::Closed, true, "",
       "passes of fig. 30's overflow heuristic a step",
       DRIFT_PARAMETER_FIELD(SoilOptions, overflow_passes), "[simulation] overflow_passes"},
  };
  return table;
}

}  // namespace drift::soil
