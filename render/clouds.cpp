#include "render/clouds.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "render/atmosphere.h"
#include "render/bsdf.h"  // henyey_greenstein
#include "render/procedural_noise.h"
#include "terrain/hash.h"

namespace drift::render {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;
// Octaves from `scale` down to scale / 64, amplitude falling by 2^-0.75 an
// octave: broad heaps with ragged edges.
constexpr double kSmallestFraction = 1.0 / 64.0;
constexpr float kHurst = 0.75f;
// Between the coverage's threshold and full density the noise rises by this
// many of its standard deviations: soft edges, dense cores.
constexpr float kRampStd = 0.8f;
// Two-term Henyey-Greenstein: water clouds scatter strongly forward (Mie,
// g ~ 0.85 for droplets; Hansen & Travis 1974) with a weaker backward lobe.
constexpr float kForwardG = 0.8f, kBackwardG = -0.3f, kForwardWeight = 0.85f;
// Diffuse light enters a slab as if at cosine 0.6 (the diffusivity factor
// 1.66 of two-stream radiative transfer).
constexpr float kDiffuseMu = 0.6f;
// The octaves' fade (render/procedural_noise.h: whole above 2 footprints,
// gone below 1) against a footprint of this fraction of the ray's width:
// half: measured best against box means (tests/render/clouds_test.cpp).
constexpr double kFootprintFraction = 0.5;

Octaves cloud_octaves(const CloudOptions& o) {
  return {o.scale, o.scale * kSmallestFraction, terrain::mix64(o.seed ^ 0xc10d5ULL)};
}

double noise_std(const Octaves& o) {
  double var = 0.0, amplitude = 1.0;
  for (int i = 0; i < octave_count(o); ++i, amplitude *= std::exp2(-kHurst))
    var += amplitude * amplitude * kNoiseStd * kNoiseStd;
  return std::sqrt(var);
}

// The (1 - coverage) quantile of the unfiltered field: sampled at 2^15
// hashed points over 64 x 64 largest wavelengths (deterministic in the seed).
float coverage_threshold(const CloudOptions& o) {
  const Octaves oct = cloud_octaves(o);
  constexpr int kSamples = 1 << 15;
  std::vector<float> v(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const std::uint64_t h = terrain::mix64(oct.seed + 0x9e3779b97f4a7c15ULL * (i + 1));
    const double x = terrain::unit_double(h) * 64.0 * o.scale;
    const double y = terrain::unit_double(terrain::mix64(h)) * 64.0 * o.scale;
    v[i] = filtered_noise(x, y, oct, 1.0f, kHurst, 0.0).value;
  }
  if (o.coverage <= 0.0) return *std::max_element(v.begin(), v.end()) + 1.0f;
  if (o.coverage >= 1.0) return *std::min_element(v.begin(), v.end()) - 1.0f;
  const auto k = static_cast<std::ptrdiff_t>((1.0 - o.coverage) * (kSamples - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// E[max(a + X, 0)] for X ~ N(0, s^2): the ramp's integral smoothed by the
// octaves the footprint dropped.
float smoothed_positive_part(float a, float s) {
  if (s <= 1e-6f) return std::max(a, 0.0f);
  const float z = a / s;
  const float cdf = 0.5f * std::erfc(-z / std::numbers::sqrt2_v<float>);
  const float pdf = std::exp(-0.5f * z * z) / std::sqrt(2.0f * kPi);
  return a * cdf + s * pdf;
}

// Single scattering of a slab seen along a view path of optical depth a with
// the sun's path b (both slant), per unit of (vertical) tau over mu: the
// integral over the slab's depth of exp(-sun path) exp(-view path). `same
// side`: the viewer on the sun's side (reflection), else transmission.
float single_scattering_geometry(float tau_over_mu, float a, float b, bool same_side) {
  if (same_side) {
    const float s = a + b;
    return s > 1e-5f ? tau_over_mu * (1.0f - std::exp(-s)) / s : tau_over_mu;
  }
  if (std::abs(a - b) < 1e-4f) return tau_over_mu * std::exp(-a);
  return tau_over_mu * (std::exp(-b) - std::exp(-a)) / (a - b);
}

}  // namespace

float cloud_phase(float cos_theta) {
  return kForwardWeight * henyey_greenstein(cos_theta, kForwardG) +
         (1.0f - kForwardWeight) * henyey_greenstein(cos_theta, kBackwardG);
}

float cloud_asymmetry() {
  return kForwardWeight * kForwardG + (1.0f - kForwardWeight) * kBackwardG;
}

float slab_reflectance(float tau, float mu0, float g) {
  // Delta-Eddington scaling (Joseph, Wiscombe & Weinman 1976): the forward
  // peak counted as unscattered, tau' = (1 - g^2) tau, g' = g / (1 + g);
  // then the conservative Eddington slab (Meador & Weaver 1980, gamma_1 =
  // 3 (1 - g') / 4, gamma_3 = (2 - 3 g' mu0) / 4):
  // R = [g1 tau' + (g3 - g1 mu0)(1 - exp(-tau' / mu0))] / (1 + g1 tau').
  const float ts = (1.0f - g * g) * tau, gs = g / (1.0f + g);
  const float g1 = 0.75f * (1.0f - gs), g3 = (2.0f - 3.0f * gs * mu0) / 4.0f;
  const float r = (g1 * ts + (g3 - g1 * mu0) * (1.0f - std::exp(-ts / mu0))) / (1.0f + g1 * ts);
  return std::clamp(r, 0.0f, 1.0f);
}

CloudLayer::CloudLayer(const CloudOptions& options, const Eigen::Vector3d& origin)
    : options_(options), origin_(origin) {
  centre_z_ = -(Atmosphere::kBottomRadius + origin.z());
  radius_ = Atmosphere::kBottomRadius + options.altitude;
  threshold_ = coverage_threshold(options);
  ramp_ = static_cast<float>(kRampStd * noise_std(cloud_octaves(options)));
}

float CloudLayer::field(double x, double y, double footprint_width, float& lost_std) const {
  const double footprint = footprint_width * kFootprintFraction;
  const Octaves oct = cloud_octaves(options_);
  const FilteredNoise n =
      filtered_noise(x + origin_.x(), y + origin_.y(), oct, 1.0f, kHurst, footprint);
  // What the footprint dropped, as value variance (filtered_noise reports
  // slope variance; per octave slope rms = amplitude x gradient rms / wavelength).
  double lost = 0.0, amplitude = 1.0, wavelength = oct.largest;
  for (int i = 0; i < octave_count(oct); ++i, amplitude *= std::exp2(-kHurst), wavelength *= 0.5) {
    const double keep = footprint > 0.0 ? std::clamp(wavelength / footprint - 1.0, 0.0, 1.0) : 1.0;
    lost += (1.0 - keep * keep) * amplitude * amplitude * kNoiseStd * kNoiseStd;
  }
  lost_std = static_cast<float>(std::sqrt(lost));
  return n.value;
}

float CloudLayer::optical_depth(double x, double y, double footprint) const {
  float lost_std = 0.0f;
  const float a = field(x, y, footprint, lost_std) - threshold_;
  // density x clamp(a / ramp, 0, 1), in expectation over the dropped octaves.
  const float ramp =
      smoothed_positive_part(a, lost_std) - smoothed_positive_part(a - ramp_, lost_std);
  return static_cast<float>(options_.density) * std::clamp(ramp / ramp_, 0.0f, 1.0f);
}

bool CloudLayer::cross(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir,
                       float max_distance, CloudCrossing& crossing) const {
  // |o + t d - c|^2 = r^2 in double: the Earth's radius swamps floats.
  const Eigen::Vector3d o(origin.x(), origin.y(), origin.z() - centre_z_);
  const Eigen::Vector3d d = dir.cast<double>();
  const double b = o.dot(d), c = o.squaredNorm() - radius_ * radius_;
  const double disc = b * b - c;
  if (disc < 0.0) return false;
  const double s = std::sqrt(disc);
  double t = -b - s;
  if (t <= 1e-3) t = -b + s;
  if (t <= 1e-3 || t >= max_distance) return false;
  // Not through the Earth (rays below the horizon that leave the scene).
  const double ground = Atmosphere::kBottomRadius;
  const double disc_ground = b * b - (o.squaredNorm() - ground * ground);
  if (disc_ground > 0.0 && -b - std::sqrt(disc_ground) > 0.0 && -b - std::sqrt(disc_ground) < t)
    return false;
  const Eigen::Vector3d p = o + t * d;
  crossing.distance = static_cast<float>(t);
  crossing.point = Eigen::Vector3f(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                   static_cast<float>(p.z() + centre_z_));
  crossing.up = (p / p.norm()).cast<float>();
  return true;
}

float CloudLayer::transmittance(const Eigen::Vector3f& p, const Eigen::Vector3f& dir, float width,
                                float spread) const {
  CloudCrossing c;
  if (!cross(p, dir, 1e30f, c)) return 1.0f;
  const float mu = std::max(std::abs(c.up.dot(dir)), 0.02f);
  const float tau = optical_depth(c.point.x(), c.point.y(), width + spread * c.distance);
  const float g = cloud_asymmetry();
  return std::exp(-(1.0f - g * g) * tau / mu);  // delta-scaled, as slab_reflectance
}

double CloudLayer::horizon_distance(double z) const {
  const double r0 = z - centre_z_, ground = Atmosphere::kBottomRadius;
  // From above: the tangent to the layer. From below: down to the tangent
  // to the ground and up again to the layer.
  if (r0 > radius_) return std::sqrt(r0 * r0 - radius_ * radius_);
  return std::sqrt(std::max(r0 * r0 - ground * ground, 0.0)) +
         std::sqrt(radius_ * radius_ - ground * ground);
}

CloudLook cloud_look(const CloudLayer& layer, const CloudCrossing& c, const Eigen::Vector3f& dir,
                     const CloudLight& light, float footprint) {
  CloudLook out;
  const CloudOptions& o = layer.options();
  const float tau = layer.optical_depth(c.point.x(), c.point.y(), footprint);
  if (tau <= 0.0f) return out;
  const float g = cloud_asymmetry(), scaled = 1.0f - g * g;
  const float mu = std::max(std::abs(c.up.dot(dir)), 0.02f);
  out.transmittance = std::exp(-scaled * tau / mu);
  const bool viewer_below = c.up.dot(dir) > 0.0f;  // the ray goes up through it
  // Ambient: the sky's light from above and the ground's from below, diffuse.
  const float rd = slab_reflectance(tau, kDiffuseMu, g);
  const float td = std::max(1.0f - rd - std::exp(-scaled * tau / kDiffuseMu), 0.0f);
  const Eigen::Vector3f near_side = viewer_below ? light.ground_up : light.sky_down;
  const Eigen::Vector3f far_side = viewer_below ? light.sky_down : light.ground_up;
  out.radiance = (rd * near_side + td * far_side) / kPi;
  const float mu0 = c.up.dot(light.sun_dir);
  if (mu0 <= 0.01f) return out;
  // Self-shadowing: the sun's way in passes over the layer towards the sun
  // (half a thickness up, horizontally thickness / 2 / tan(elevation)).
  const Eigen::Vector3f towards = light.sun_dir - mu0 * c.up;
  const float reach =
      std::min(0.5f * static_cast<float>(o.thickness) / mu0, static_cast<float>(o.scale));
  const Eigen::Vector3f q = c.point + towards * reach;
  const float tau_sun = 0.5f * (tau + layer.optical_depth(q.x(), q.y(), footprint));
  const float r = slab_reflectance(tau_sun, mu0, g);
  const float t_diffuse = std::max(1.0f - r - std::exp(-scaled * tau_sun / mu0), 0.0f);
  const bool sun_side = !viewer_below;  // the sun is above the layer here
  float sun = (sun_side ? r : t_diffuse) * mu0 / kPi;
  // The single scattering's departure from isotropic: bright rims towards
  // the sun, the phase function's shape on the cloud.
  const float cos_theta = dir.dot(light.sun_dir);  // 1: looking into the sun through it
  const float a = tau / mu, b = tau_sun / mu0;
  sun += (cloud_phase(cos_theta) - 1.0f / (4.0f * kPi)) *
         single_scattering_geometry(tau / mu, a, b, sun_side);
  out.radiance += light.sun * std::max(sun, 0.0f);
  return out;
}

}  // namespace drift::render
