// Colour helpers shared by the integrator and the reflectance models.
#pragma once

#include <Eigen/Core>

namespace drift::render {

// Luminance of linear sRGB (Rec. 709 weights).
inline float luminance(const Eigen::Vector3f& rgb) {
  return 0.2126f * rgb.x() + 0.7152f * rgb.y() + 0.0722f * rgb.z();
}

}  // namespace drift::render
