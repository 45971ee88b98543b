#include "snow/adhesion_coverage.h"

#include <algorithm>
#include <cmath>

#include "terrain/angles.h"

namespace drift::snow {

double thin_coverage(double depth, const CoverageOptions& o) {
  return std::clamp(depth / o.thin_depth, 0.0, 1.0);
}

double adhesion_coverage(const Eigen::Vector3d& n, double facing, double amount,
                         const CoverageOptions& o) {
  const double phi = terrain::degrees(std::acos(std::clamp(n.z(), -1.0, 1.0)));
  const double steep =
      std::clamp((phi - o.adhesion_min_slope) / (90.0 - o.adhesion_min_slope), 0.0, 1.0);
  const double saturation = 1.0 - std::exp(-amount / o.adhesion_depth);
  return o.adhesion * steep * std::clamp(facing, 0.0, 1.0) * saturation;
}

}  // namespace drift::snow
