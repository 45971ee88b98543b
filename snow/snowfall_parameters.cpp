#include "snow/snowfall_parameters.h"

#include <limits>

namespace drift::snow {

using terrain::Ends;

const std::vector<SnowfallParameter>& snowfall_parameters() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  static const std::vector<SnowfallParameter> table = {
      {"azimuth_deg", "--direction AZ", 0, 360, Ends::Closed, false, "degrees",
       "where the snow comes from, like a sun's azimuth (0 north, 90 east)",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, azimuth_deg)},
      {"elevation_deg", "--direction EL", 0, 90, Ends::OpenLow, false, "degrees",
       "the snow's elevation above the horizon (90: straight down)",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, elevation_deg)},
      {"spread_deg", "--spread", 0, 30, Ends::Closed, false, "degrees",
       "standard deviation of the direction jitter (paper 003 2.1(3))",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, spread_deg)},
      {"maps", "--maps", 1, 1024, Ends::Closed, true, "", "number of jittered depth maps",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, maps)},
      {"rate_m_per_h", "--rate", 0, 10, Ends::OpenLow, false, "m/h",
       "fresh snow on open flat ground per hour",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, rate_m_per_h)},
      {"hours", "--hours", 0, 1e4, Ends::OpenLow, false, "h", "duration of the snowfall",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, hours)},
      {"repose_deg", "--repose", 0, 90, Ends::Open, false, "degrees", "angle of repose of snow",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, repose_deg)},
      {"mesh_max_edge", "--mesh-edge", 0, inf, Ends::Closed, false, "m",
       "split object edges longer than this (0 keeps the meshes)",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, mesh_max_edge)},
      {"occlusion.object_texel", "--object-texel", 0, inf, Ends::Closed, false, "m",
       "texel of the object depth maps (0: the largest object's extent / 1024, at most half a "
       "cell)",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, occlusion.object_texel)},
      {"coverage.thin_depth", "--thin-depth", 0, 10, Ends::OpenLow, false, "m",
       "snow thinner than this shows as scattered flakes",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, coverage.thin_depth)},
      {"coverage.adhesion", "--adhesion", 0, 1, Ends::Closed, false, "",
       "coverage of flakes stuck on walls facing the snow",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, coverage.adhesion)},
      {"max_iterations", "--max-iterations", 1, 1e9, Ends::Closed, true, "",
       "limit on stabilisation passes", DRIFT_PARAMETER_FIELD(SnowfallOptions, max_iterations)},
      {"coarse_levels", "--coarse-levels", 0, 16, Ends::Closed, true, "",
       "settle the ground snow first on this many levels of 2 x 2 blocks: faster on large "
       "rasters, the state a few cm from the default's (docs/snowfall.md)",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, coarse_levels)},
      {"direct_layers", "--direct-layers", 1, 1024, Ends::Closed, true, "",
       "with --stabilise direct: the snow settled in this many equal layers, each on the "
       "last's state at rest: nearer the passes' state, cost x N (docs/snowfall.md)",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, direct_layers)},
      // The library's own: no flag.
      {"occlusion.ground_samples", "", 0, 16, Ends::Closed, true, "",
       "depth-map samples K for cells near objects (0: a cell / 2 texels)",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, occlusion.ground_samples)},
      {"coverage.adhesion_min_slope", "", 0, 90, Ends::OpenHigh, false, "degrees",
       "slope from horizontal where flakes start to stick",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, coverage.adhesion_min_slope)},
      {"coverage.adhesion_depth", "", 0, inf, Ends::OpenLow, false, "m",
       "snowfall that makes 63 % of the full adhesion",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, coverage.adhesion_depth)},
      {"tolerance", "", 0, inf, Ends::OpenLow, false, "m",
       "object stabilisation stops when nothing moves more per pass",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, tolerance)},
      {"ground_tolerance", "", 0, inf, Ends::OpenLow, false, "m",
       "on the ground, a pair steeper than repose by less, or a film thinner, is stable",
       DRIFT_PARAMETER_FIELD(SnowfallOptions, ground_tolerance)},
  };
  return table;
}

}  // namespace drift::snow
