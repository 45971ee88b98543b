#include "snow/snowfall_directions.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <string>

#include "terrain/angles.h"
#include "terrain/direction.h"
#include "terrain/error.h"
#include "terrain/hash.h"

namespace drift::snow {

namespace {

double uniform(std::uint64_t seed, std::uint64_t index) {
  return terrain::unit_double(terrain::mix64(terrain::mix64(seed) ^ index));
}
}  // namespace

std::vector<FallDirection> jittered_directions(double azimuth_deg, double elevation_deg,
                                               double spread_deg, int maps, std::uint64_t seed) {
  if (maps < 1) throw Error("the number of snowfall maps must be at least 1");
  // Where the snow comes from, like a sun position.
  const Eigen::Vector3d mean = terrain::direction_from_az_el(azimuth_deg, elevation_deg);
  std::vector<FallDirection> out(static_cast<std::size_t>(maps));
  if (maps == 1 || spread_deg <= 0.0) {
    for (auto& d : out) d = {mean, 1.0f / static_cast<float>(maps), 0.0};
  } else {
    // Basis of the plane normal to the mean direction.
    const Eigen::Vector3d helper =
        std::abs(mean.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    const Eigen::Vector3d e1 = helper.cross(mean).normalized(), e2 = mean.cross(e1);
    const double sigma = terrain::radians(spread_deg), cone = 2.5 * sigma;
    const double golden = (3.0 - std::sqrt(5.0)) * std::numbers::pi;  // golden angle
    const double rotation = 2.0 * std::numbers::pi * uniform(seed, 0);
    std::vector<double> raw(out.size());
    for (int k = 0; k < maps; ++k) {
      // Equal-area strata in the disc of angles: radius^2 uniform in stratum k.
      const double alpha = cone * std::sqrt((k + uniform(seed, 1 + k)) / maps);
      const double phi = rotation + golden * k;
      const Eigen::Vector3d d =
          (std::cos(alpha) * mean + std::sin(alpha) * (std::cos(phi) * e1 + std::sin(phi) * e2))
              .normalized();
      raw[k] = std::exp(-alpha * alpha / (2.0 * sigma * sigma));
      out[k].toward_source = d;
      out[k].angle_rad = alpha;
    }
    double total = 0.0;
    for (double r : raw) total += r;
    for (int k = 0; k < maps; ++k) out[k].weight = static_cast<float>(raw[k] / total);
  }
  for (const auto& d : out) {
    if (d.toward_source.z() < std::sin(terrain::radians(1.0))) {
      throw Error("snowfall elevation " + std::to_string(elevation_deg) + " with spread " +
                  std::to_string(spread_deg) +
                  " gives directions less than 1 degree above the horizon; raise the elevation "
                  "or lower the spread (elevation - 2.5 x spread must stay above 1)");
    }
  }
  return out;
}

}  // namespace drift::snow
