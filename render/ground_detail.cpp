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
  const FilteredNoise n =
      filtered_noise(x, y, kAlbedoOctaves, amplitude, kAlbedoHurst, footprint);
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

DetailedGround ground_detail(const Material& material, double x, double y,
                             const Eigen::Vector3f& normal, double footprint) {
  const GroundDetail& d = material.detail;
  DetailedGround out{material.albedo, normal, material.roughness};
  if (d.variation > 0.0f) {
    // Brightness over all octaves, and a weaker warm-cold hue shift (oxide
    // stains against grey lichen, sun-dried against green growth).
    const float f = albedo_factor(d, x, y, footprint);
    const float hue =
        0.12f * d.variation *
        filtered_noise(x, y, {64.0, 8.0, kHueSeed}, 1.0f / kNoiseStd, 0.0f, footprint).value /
        2.0f;  // 4 octaves of equal amplitude: a standard deviation of 1
    out.albedo = (material.albedo * f)
                     .cwiseProduct(Eigen::Vector3f(1.0f + hue, 1.0f, 1.0f - hue))
                     .cwiseMax(0.0f)
                     .cwiseMin(0.98f);
  }
  if (d.bump > 0.0f && normal.z() > 1e-3f) {
    const DetailSlope s = detail_slope(d, x, y, footprint);
    // Surface z = Z(x, y) + h(x, y): n ~ (-(Zx + hx), -(Zy + hy), 1).
    const Eigen::Vector3f base = normal / normal.z();
    out.normal = Eigen::Vector3f(base.x() - s.slope.x(), base.y() - s.slope.y(), 1.0f).normalized();
    const float sigma = std::atan(std::sqrt(s.lost_variance));
    out.roughness = std::min(std::hypot(material.roughness, sigma), kMaxRoughness);
  }
  return out;
}

}  // namespace drift::render
