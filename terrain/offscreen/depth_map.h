// An orthographic depth map along a direction (after Segal et al. 1992),
// shared by the stages that render depth off-screen: snowfall treats its
// direction as a light, and a point hidden from it by something nearer the
// source is in "shadow" and gets no snow (paper 003, 2.1(1)); marks look up
// from below the ground, so the surface nearest the source is an object's
// bottom (paper 000, 3.3).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

namespace drift::terrain {

// Light space: a = p.u, b = p.v across the map, c = p.w towards the source.
struct LightFrame {
  Eigen::Vector3d u, v, w;

  // u follows east and v north when w is straight up, so a vertical map is the raster.
  static LightFrame toward(const Eigen::Vector3d& toward_source);
  Eigen::Vector3d project(const Eigen::Vector3d& p) const { return {p.dot(u), p.dot(v), p.dot(w)}; }
};

struct DepthMap {
  LightFrame frame;
  double a0 = 0, b0 = 0;  // light-space corner of texel (0, 0)
  double texel = 1;       // metres
  int width = 0, height = 0;
  double c_ref = 0;        // depths are stored relative to it (float precision)
  std::vector<float> top;  // per texel: largest c - c_ref (surface nearest the source); -inf empty

  static constexpr float kEmpty = -std::numeric_limits<float>::infinity();

  bool contains(double a, double b) const {
    return a >= a0 && b >= b0 && a < a0 + width * texel && b < b0 + height * texel;
  }
  // Nearest texel; kEmpty outside the map.
  float top_at(double a, double b) const;

  // Is the point p (local frame) with unit normal n seen from the source? Slope-scaled
  // bias: across half a texel diagonal a plane tilted by phi from w changes depth by
  // up to texel / sqrt(2) x tan(phi), so self-comparisons never fall in shadow (no
  // acne), while occluders farther than that keep their shadow (no peter-panning
  // beyond one texel). Faces turned away from the source (n.w <= 0) are unlit.
  bool lit(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const;
  // With a bias (m) chosen by the caller, e.g. from the steepest of several normals
  // where surfaces meet at a concave kink.
  bool lit_biased(const Eigen::Vector3d& p, double bias) const;
};

// Slope-scaled bias for a surface whose unit normal makes cos_phi with w.
double depth_bias(double texel, double cos_phi);

}  // namespace drift::terrain
