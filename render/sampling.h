// Warps from the unit square to directions, shared by the integrator and the
// reflectance models.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace drift::render {

// An orthonormal basis (t, b) around unit n (Duff et al. 2017, "Building an
// orthonormal basis, revisited").
inline void basis(const Eigen::Vector3f& n, Eigen::Vector3f& t, Eigen::Vector3f& b) {
  const float sign = std::copysign(1.0f, n.z());
  const float a = -1.0f / (sign + n.z());
  const float c = n.x() * n.y() * a;
  t = Eigen::Vector3f(1.0f + sign * n.x() * n.x() * a, sign * c, -sign * n.x());
  b = Eigen::Vector3f(c, sign + n.y() * n.y() * a, -n.y());
}

// The direction with cosine `cos_t` to unit `axis` and azimuth `phi` about it.
inline Eigen::Vector3f around(const Eigen::Vector3f& axis, float cos_t, float phi) {
  const float sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
  Eigen::Vector3f t, b;
  basis(axis, t, b);
  return (t * (sin_t * std::cos(phi)) + b * (sin_t * std::sin(phi)) + axis * cos_t).normalized();
}

// Cosine-weighted direction about n: pdf cos / pi (Malley's method).
inline Eigen::Vector3f cosine_sample(const Eigen::Vector3f& n, float u1, float u2) {
  return around(n, std::sqrt(std::max(0.0f, 1.0f - u1)), 2.0f * std::numbers::pi_v<float> * u2);
}

// Uniform direction in the cone of half-angle with cosine `cos_max` around `axis`.
inline Eigen::Vector3f cone_sample(const Eigen::Vector3f& axis, float cos_max, float u1, float u2) {
  return around(axis, 1.0f - u1 * (1.0f - cos_max), 2.0f * std::numbers::pi_v<float> * u2);
}

}  // namespace drift::render
