#include "snow/cover_parameters.h"

#include <limits>

namespace drift::snow {

using terrain::Ends;

const std::vector<CoverParameter>& cover_parameters() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  static const std::vector<CoverParameter> table = {
      {"region", "--region", 0, 32, Ends::OpenLow, false, "50 m cells",
       "smoothing region n in the paper's 50 m cells (a diamond of 4n + 2n(n-1) points), "
       "widened to n x 50 m / cell size on the DEM at hand",
       DRIFT_PARAMETER_FIELD(CoverOptions, region)},
      {"region_cells", "--region-cells", 0, 256, Ends::Closed, true, "cells",
       "above 0: the smoothing region n in this DEM's own cells instead of --region",
       DRIFT_PARAMETER_FIELD(CoverOptions, region_cells)},
      {"iterations", "--iterations", 0, 100, Ends::Closed, true, "", "smoothing passes k",
       DRIFT_PARAMETER_FIELD(CoverOptions, iterations)},
      {"radius_m", "--radius", 0, inf, Ends::OpenLow, false, "m",
       "probe radius r (the paper's 5.5 at its 0.1 per 50 m cell)",
       DRIFT_PARAMETER_FIELD(CoverOptions, radius_m)},
      {"radius_cells", "--radius-cells", 0, inf, Ends::Closed, false, "cells",
       "above 0: the probe radius in this DEM's cells instead of --radius (the paper's 5.5 is 55)",
       DRIFT_PARAMETER_FIELD(CoverOptions, radius_cells)},
      {"floor", "--floor", 0, 1, Ends::Closed, false, "",
       "b: how much rock shows where the TSA is 0", DRIFT_PARAMETER_FIELD(CoverOptions, floor)},
      {"sun_range_deg", "--sun-range", 0, 90, Ends::Closed, false, "degrees",
       "theta1: slopes facing within this of the sun lose snow (0: no sun step)",
       DRIFT_PARAMETER_FIELD(CoverOptions, sun_range_deg)},
      {"band_m", "--band", 0, inf, Ends::OpenLow, false, "m",
       "with --snow-line: the width of its transition from no snow to full",
       DRIFT_PARAMETER_FIELD(CoverOptions, band_m)},
  };
  return table;
}

}  // namespace drift::snow
