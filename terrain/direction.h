// Directions on the sky as the user gives them (degrees at the interface):
// azimuth clockwise from north, elevation above the horizon. The sun's
// direction (render) and the direction snow comes from (snow) are both this.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "terrain/angles.h"

namespace drift::terrain {

// Unit vector (x east, y north, z up) pointing towards azimuth `azimuth_deg`
// (clockwise from north) at `elevation_deg` above the horizon; (any, 90) is
// straight up.
inline Eigen::Vector3d direction_from_az_el(double azimuth_deg, double elevation_deg) {
  const double az = radians(azimuth_deg), el = radians(elevation_deg);
  return {std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el)};
}

}  // namespace drift::terrain
