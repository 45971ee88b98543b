#include "terrain/local_frame.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "terrain/error.h"

namespace drift::terrain {

LocalFrame local_frame(const HeightField& dem, const std::string& what, double z_scale) {
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (float v : dem.values())
    if (!std::isnan(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!std::isfinite(lo)) throw Error(what + " holds no valid height (all nodata)");
  LocalFrame f;
  f.lowest = lo;
  f.highest = hi;
  const auto centre = dem.geo().cell_center((dem.width() - 1) / 2.0, (dem.height() - 1) / 2.0);
  f.origin = Eigen::Vector3d(centre[0], centre[1], static_cast<double>(lo) * z_scale);
  const auto nw = dem.geo().cell_center(0, 0);
  f.x0 = nw[0] - f.origin.x();
  f.y0 = nw[1] - f.origin.y();
  return f;
}

}  // namespace drift::terrain
