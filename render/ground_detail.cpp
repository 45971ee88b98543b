#include "render/ground_detail.h"

#include <algorithm>
#include <cmath>

#include "render/procedural_noise.h"

namespace drift::render {

namespace {

// Seeds of the three noises (fixed: the ground is part of the scene, not of
// the render's sampling).
constexpr std::uint64_t kAlbedoSeed = 0x6a1bed0;
constexpr std::uint64_t kHueSeed = 0x6a1bed1;
constexpr std::uint64_t kReliefSeed = 0x6a1bed2;

// Albedo octaves: 128 m down to 0.5 m, Hurst 0.3.
constexpr Octaves kAlbedoOctaves{128.0, 0.5, kAlbedoSeed};
constexpr float kAlbedoHurst = 0.3f;
// Relief octaves: scale down to scale / 32, height amplitudes growing with
// wavelength^0.6 (Hurst 0.6; natural rock surfaces are self-affine with
// Hurst exponents of about 0.5-0.9, Power & Tullis 1991, J. Geophys. Res.
// 96(B1), 415-424):
// the slope is carried mostly by the small octaves, so the largest
// octave's height (about 0.1 bump x scale) barely tilts a whole cell.
constexpr double kReliefRange = 32.0;
constexpr float kReliefHurst = 0.6f;

// Sum over octaves of (wavelength / largest)^(2 hurst): the variance of the
// octave sum is kNoiseStd^2 a^2 times this.
float octave_energy(const Octaves& o, float hurst) {
  float sum = 0.0f;
  double w = o.largest;
  for (int i = 0; i < octave_count(o); ++i, w *= 0.5)
    sum += static_cast<float>(std::pow(w / o.largest, 2.0 * hurst));
  return sum;
}

}  // namespace

float albedo_factor(const GroundDetail& detail, double x, double y, double footprint) {
  if (!(detail.variation > 0.0f)) return 1.0f;
  static const float energy = octave_energy(kAlbedoOctaves, kAlbedoHurst);
  const float amplitude = detail.variation / (kNoiseStd * std::sqrt(energy));
  const FilteredNoise n = filtered_noise(x, y, kAlbedoOctaves, amplitude, kAlbedoHurst, footprint);
  return std::clamp(1.0f + n.value, 0.2f, 2.0f);
}

DetailSlope detail_slope(const GroundDetail& detail, double x, double y, double footprint) {
  DetailSlope out;
  if (!(detail.bump > 0.0f) || !(detail.scale > 0.0f)) return out;
  const Octaves octaves{detail.scale, detail.scale / kReliefRange, kReliefSeed};
  // Height amplitude of the largest octave for a total rms slope `bump`:
  // octave i's rms slope is a (w_i / scale)^(H - 1) kNoiseGradientRms / scale.
  static const float energy = octave_energy(octaves, kReliefHurst - 1.0f);
  const float amplitude = detail.bump * detail.scale / (kNoiseGradientRms * std::sqrt(energy));
  const FilteredNoise n = filtered_noise(x, y, octaves, amplitude, kReliefHurst, footprint);
  out.slope = n.gradient;
  out.lost_variance = n.lost_slope_variance;
  return out;
}

namespace {

// Triplanar projection (Geiss 2007, GPU Gems 3, ch. 1 "Generating complex
// procedural terrains using the GPU"): the noise is read on the three axis
// planes and blended by how squarely the surface faces each, so a steep face
// gets its detail from a vertical plane instead of the map's plane stretched
// down its fall line (streaks). A plane counts only where its axis is within
// ~66 degrees of the normal (|n_i| > 0.4), weight (|n_i| - 0.4)^2: gentle
// ground (up to ~24-34 degrees) reads the map's plane alone, exactly as
// before. Blends are divided by the root of the summed squared weights so a
// blend of independent planes keeps one plane's variance.
constexpr float kPlaneDead = 0.4f;

struct Planes {
  // 0: map plane (x, y), axis z; 1: (y, z), axis x; 2: (x, z), axis y.
  float w[3] = {0, 0, 0};
  bool map_only = true;
};

Planes plane_weights(const Eigen::Vector3f& n) {
  Planes p;
  const float a[3] = {std::abs(n.z()), std::abs(n.x()), std::abs(n.y())};
  float sum2 = 0.0f;
  for (int i = 0; i < 3; ++i) {
    const float e = std::max(a[i] - kPlaneDead, 0.0f);
    p.w[i] = e * e;
    sum2 += p.w[i] * p.w[i];
  }
  p.map_only = p.w[1] == 0.0f && p.w[2] == 0.0f;
  for (float& w : p.w) w /= std::sqrt(sum2);
  return p;
}

// Plane i's coordinates of (x, y, z), each plane shifted so that the three
// noises are independent.
Eigen::Vector2d plane_uv(int i, double x, double y, double z) {
  if (i == 0) return {x, y};
  if (i == 1) return {y + 1531.7, z + 2711.3};
  return {x + 3917.1, z + 4409.9};
}

// The albedo factor and the bumped normal of a face steep enough for the
// vertical planes.
void triplanar_detail(const GroundDetail& d, const Planes& planes, double x, double y, double z,
                      const Eigen::Vector3f& normal, double footprint, float& factor,
                      DetailedGround& out) {
  float f = 0.0f, lost = 0.0f;
  Eigen::Vector3f tilt(0, 0, 0);
  const float axis[3] = {std::abs(normal.z()), std::abs(normal.x()), std::abs(normal.y())};
  for (int i = 0; i < 3; ++i) {
    if (planes.w[i] == 0.0f) continue;
    const Eigen::Vector2d uv = plane_uv(i, x, y, z);
    f += planes.w[i] * (albedo_factor(d, uv.x(), uv.y(), footprint) - 1.0f);
    if (!(d.bump > 0.0f)) continue;
    const DetailSlope s = detail_slope(d, uv.x(), uv.y(), footprint);
    // The relief's gradient in plane i, as a tilt across the plane's axis
    // (for the map plane n - n_z (hx, hy, 0), the heightfield's bump).
    const Eigen::Vector3f g = i == 0   ? Eigen::Vector3f(s.slope.x(), s.slope.y(), 0.0f)
                              : i == 1 ? Eigen::Vector3f(0.0f, s.slope.x(), s.slope.y())
                                       : Eigen::Vector3f(s.slope.x(), 0.0f, s.slope.y());
    tilt += planes.w[i] * axis[i] * g;
    lost += planes.w[i] * planes.w[i] * s.lost_variance;
  }
  factor = std::clamp(1.0f + f, 0.2f, 2.0f);
  if (d.bump > 0.0f) {
    out.normal = (normal - tilt).normalized();
    out.roughness = std::min(std::hypot(out.roughness, std::atan(std::sqrt(lost))), kMaxRoughness);
  }
}

}  // namespace

DetailedGround ground_detail(const Material& material, double x, double y, double z,
                             const Eigen::Vector3f& normal, double footprint) {
  const GroundDetail& d = material.detail;
  DetailedGround out{material.albedo, normal, material.roughness};
  const Planes planes = plane_weights(normal);
  float f = 1.0f;
  if (!planes.map_only && (d.variation > 0.0f || d.bump > 0.0f)) {
    triplanar_detail(d, planes, x, y, z, normal, footprint, f, out);
    if (!(d.variation > 0.0f)) f = 1.0f;
  } else {
    if (d.variation > 0.0f) f = albedo_factor(d, x, y, footprint);
    if (d.bump > 0.0f && normal.z() > 1e-3f) {
      const DetailSlope s = detail_slope(d, x, y, footprint);
      // Surface z = Z(x, y) + h(x, y): n ~ (-(Zx + hx), -(Zy + hy), 1).
      const Eigen::Vector3f base = normal / normal.z();
      out.normal =
          Eigen::Vector3f(base.x() - s.slope.x(), base.y() - s.slope.y(), 1.0f).normalized();
      const float sigma = std::atan(std::sqrt(s.lost_variance));
      out.roughness = std::min(std::hypot(material.roughness, sigma), kMaxRoughness);
    }
  }
  if (d.variation > 0.0f) {
    // Brightness over all octaves, and a weaker warm-cold hue shift (oxide
    // stains against grey lichen, sun-dried against green growth), the hue
    // on the map's plane only (it is weak and broad).
    const float hue =
        0.12f * d.variation *
        filtered_noise(x, y, {64.0, 8.0, kHueSeed}, 1.0f / kNoiseStd, 0.0f, footprint).value /
        2.0f;  // 4 octaves of equal amplitude: a standard deviation of 1
    out.albedo = (material.albedo * f)
                     .cwiseProduct(Eigen::Vector3f(1.0f + hue, 1.0f, 1.0f - hue))
                     .cwiseMax(0.0f)
                     .cwiseMin(0.98f);
  }
  return out;
}

}  // namespace drift::render
