// Reflectance of rough diffuse surfaces.
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace drift::render {

// Oren & Nayar (1994), "Generalization of Lambert's reflectance model", the
// qualitative model (their eq. 30): the factor by which a surface of facet
// slope deviation `sigma` (radians) reflects more or less than Lambert's
// albedo/pi, for unit normal n, light direction wi and view direction wo (both
// pointing away from the surface). sigma = 0 gives exactly 1 (Lambert). Uses
// cos(phi_i - phi_o) sin(alpha) tan(beta) = max(0, s) / max(cos_i, cos_o) with
// s = wi.wo - cos_i cos_o, which needs no trigonometry.
inline float oren_nayar_factor(const Eigen::Vector3f& n, const Eigen::Vector3f& wi,
                               const Eigen::Vector3f& wo, float sigma) {
  if (sigma <= 0.0f) return 1.0f;
  const float s2 = sigma * sigma;
  const float a = 1.0f - 0.5f * s2 / (s2 + 0.33f);
  const float b = 0.45f * s2 / (s2 + 0.09f);
  const float cos_i = std::max(n.dot(wi), 0.0f), cos_o = std::max(n.dot(wo), 0.0f);
  const float s = wi.dot(wo) - cos_i * cos_o;
  const float t = std::max({cos_i, cos_o, 1e-6f});
  return a + b * std::max(s, 0.0f) / t;
}

}  // namespace drift::render
