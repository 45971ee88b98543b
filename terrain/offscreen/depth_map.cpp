#include "terrain/offscreen/depth_map.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace drift::terrain {

LightFrame LightFrame::toward(const Eigen::Vector3d& toward_source) {
  LightFrame f;
  f.w = toward_source.normalized();
  // East projected off w; north when w runs east (never for a fall above 1 degree
  // elevation, but keep it total).
  Eigen::Vector3d u = Eigen::Vector3d::UnitX() - f.w.x() * f.w;
  if (u.norm() < 1e-6) u = Eigen::Vector3d::UnitY() - f.w.y() * f.w;
  f.u = u.normalized();
  f.v = f.w.cross(f.u);
  return f;
}

float DepthMap::top_at(double a, double b) const {
  if (!contains(a, b)) return kEmpty;
  const int i = std::min(static_cast<int>((a - a0) / texel), width - 1);
  const int j = std::min(static_cast<int>((b - b0) / texel), height - 1);
  return top[static_cast<std::size_t>(j) * width + i];
}

double depth_bias(double texel, double cos_phi) {
  const double c = std::clamp(cos_phi, 0.05, 1.0);  // tan clamped at ~87 degrees
  const double tan_phi = std::sqrt(1.0 - c * c) / c;
  return texel * (0.7072 * tan_phi + 0.01);
}

bool DepthMap::lit(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
  const double cos_phi = n.dot(frame.w);
  if (cos_phi <= 0.0) return false;
  return lit_biased(p, depth_bias(texel, cos_phi));
}

bool DepthMap::lit_biased(const Eigen::Vector3d& p, double bias) const {
  const Eigen::Vector3d q = frame.project(p);
  const float top = top_at(q.x(), q.y());
  if (top == kEmpty) return true;
  return q.z() - c_ref >= static_cast<double>(top) - bias;
}

}  // namespace drift::terrain
