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
// The flattest a ray meets the layer (cosine to its vertical): from a
// mountain, the layer's horizon is about this steep.
constexpr float kMinMu = 0.02f;
// Steps of the sun's march over the neighbouring columns (CloudLayer::sun_shadow).
constexpr int kShadowSteps = 4;

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

float CloudLayer::field(double x, double y, double footprint_width, float& lost_std,
                        Eigen::Vector2f* gradient) const {
  const double footprint = footprint_width * kFootprintFraction;
  const Octaves oct = cloud_octaves(options_);
  const FilteredNoise n =
      filtered_noise(x + origin_.x(), y + origin_.y(), oct, 1.0f, kHurst, footprint);
  if (gradient) *gradient = n.gradient;
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

float CloudLayer::optical_depth(double x, double y, double footprint,
                                Eigen::Vector2f* gradient) const {
  return covered(x, y, footprint, gradient).mean();
}

CloudSample CloudLayer::covered(double x, double y, double footprint,
                                Eigen::Vector2f* gradient) const {
  float lost_std = 0.0f;
  Eigen::Vector2f field_gradient;
  const float a =
      field(x, y, footprint, lost_std, gradient ? &field_gradient : nullptr) - threshold_;
  // density x clamp(a / ramp, 0, 1), in expectation over the dropped octaves.
  const float ramp =
      smoothed_positive_part(a, lost_std) - smoothed_positive_part(a - ramp_, lost_std);
  const float density = static_cast<float>(options_.density);
  if (gradient) {
    // d/da of the smoothed ramp: the share of the dropped octaves' Gaussian
    // between a - ramp and a, over the ramp.
    const float s = std::max(lost_std, 1e-6f) * std::numbers::sqrt2_v<float>;
    const float slope = 0.5f * (std::erfc(-(a) / s) - std::erfc(-(a - ramp_) / s)) / ramp_;
    *gradient = density * slope * field_gradient;
  }
  // The share of the footprint under cloud, P(a + X > 0), and the optical
  // depth there: the mean over the cloudy part. Transmittance is convex in
  // tau, so a footprint half clear and half opaque passes half, where the
  // mean tau alone would pass almost nothing at a slant near the horizon.
  CloudSample out;
  const float mean = density * std::clamp(ramp / ramp_, 0.0f, 1.0f);
  out.cover = lost_std > 1e-6f ? 0.5f * std::erfc(-a / (lost_std * std::numbers::sqrt2_v<float>))
                               : (a > 0.0f ? 1.0f : 0.0f);
  out.tau = out.cover > 1e-6f ? std::min(mean / out.cover, density) : 0.0f;
  if (out.tau <= 0.0f) out.cover = 0.0f;
  return out;
}

float CloudLayer::top_height(float tau) const {
  return static_cast<float>(options_.thickness) * tau / static_cast<float>(options_.density);
}

float CloudLayer::sun_shadow(const Eigen::Vector3f& point, const Eigen::Vector3f& up,
                             const Eigen::Vector3f& sun_dir, float tau, float footprint) const {
  // The 2.5-D cloud: each column's top stands top_height(tau) above the
  // layer's base. The sun's ray leaves this column's top and passes over the
  // neighbours towards the sun; where a neighbour's top is higher than the
  // ray, the ray runs through it. Marched in kShadowSteps steps over at most
  // a largest wavelength; the optical depth inside is the column's density
  // per metre of height (density / thickness).
  const float mu0 = up.dot(sun_dir);
  if (mu0 <= 0.01f) return 1.0f;
  const Eigen::Vector3f across = sun_dir - mu0 * up;
  const float sin0 = across.norm();
  if (sin0 < 1e-4f) return 1.0f;  // sun overhead: nothing stands between
  const Eigen::Vector3f towards = across / sin0;
  const float tan0 = mu0 / sin0;  // the ray's rise per metre across
  const float thickness = static_cast<float>(options_.thickness);
  const float reach =
      std::min(thickness / std::max(tan0, 1e-3f), static_cast<float>(options_.scale));
  const float step = reach / kShadowSteps;
  const float per_metre = static_cast<float>(options_.density) / thickness;
  const float start = top_height(tau);
  float depth = 0.0f;
  for (int k = 1; k <= kShadowSteps; ++k) {
    const float s = step * (static_cast<float>(k) - 0.5f);
    const Eigen::Vector3f q = point + towards * s;
    const float over = top_height(optical_depth(q.x(), q.y(), footprint)) - (start + s * tan0);
    // The ray's path through this step inside the neighbour: the share of
    // the step's rise it spends below the neighbour's top.
    if (over > 0.0f) depth += per_metre * std::min(over, step * tan0) / mu0;
  }
  const float g = cloud_asymmetry();
  return std::exp(-(1.0f - g * g) * depth);
}

float CloudLayer::mean_sun_transmittance(const Eigen::Vector3f& sun_dir) const {
  // The layer's shadow averaged over the ground: its direct transmittance
  // towards the sun at 4096 hashed points over 16 x 16 largest wavelengths.
  if (sun_dir.z() <= 0.01f) return 1.0f;
  const float g = cloud_asymmetry();
  constexpr int kSamples = 4096;
  double sum = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    const std::uint64_t h = terrain::mix64(options_.seed * 0x2545f4914f6cdd1dULL + i + 1);
    const double x = terrain::unit_double(h) * 16.0 * options_.scale;
    const double y = terrain::unit_double(terrain::mix64(h)) * 16.0 * options_.scale;
    sum += std::exp(-(1.0f - g * g) * optical_depth(x, y, 0.0) / sun_dir.z());
  }
  return static_cast<float>(sum / kSamples);
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

float grazing_footprint(float width, float mu) { return width / std::max(mu, kMinMu); }

float CloudLayer::transmittance(const Eigen::Vector3f& p, const Eigen::Vector3f& dir, float width,
                                float spread) const {
  CloudCrossing c;
  if (!cross(p, dir, 1e30f, c)) return 1.0f;
  const float mu = std::max(std::abs(c.up.dot(dir)), kMinMu);
  const CloudSample s =
      covered(c.point.x(), c.point.y(), grazing_footprint(width + spread * c.distance, mu));
  const float g = cloud_asymmetry();
  // Delta-scaled, as slab_reflectance; the clear share passes whole.
  return 1.0f - s.cover + s.cover * std::exp(-(1.0f - g * g) * s.tau / mu);
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
  const float mu = std::max(std::abs(c.up.dot(dir)), kMinMu);
  footprint = grazing_footprint(footprint, mu);
  Eigen::Vector2f gradient;
  const CloudSample cs = layer.covered(c.point.x(), c.point.y(), footprint, &gradient);
  if (cs.cover <= 0.0f) return out;
  // The cloudy share of the footprint as a cloud of its own optical depth;
  // the clear share passes what is behind (see CloudLayer::covered).
  const float tau = cs.tau, cover = cs.cover;
  const float g = cloud_asymmetry(), scaled = 1.0f - g * g;
  out.transmittance = 1.0f - cover + cover * std::exp(-scaled * tau / mu);
  const bool viewer_below = c.up.dot(dir) > 0.0f;  // the ray goes up through it
  // Ambient: the sky's light from above and the ground's from below, diffuse.
  const float rd = slab_reflectance(tau, kDiffuseMu, g);
  const float td = std::max(1.0f - rd - std::exp(-scaled * tau / kDiffuseMu), 0.0f);
  const Eigen::Vector3f near_side = viewer_below ? light.ground_up : light.sky_down;
  const Eigen::Vector3f far_side = viewer_below ? light.sky_down : light.ground_up;
  out.radiance = cover * (rd * near_side + td * far_side) / kPi;
  const float mu0 = c.up.dot(light.sun_dir);
  if (mu0 <= 0.01f) return out;
  const bool sun_side = !viewer_below;  // the sun is above the layer here
  // Seen from above, the sun falls on the 2.5-D cloud's top (render/clouds.h):
  // its slope, from the column heights' gradient, turns it towards or away
  // from the sun (bright sunward flanks, darker lee sides); from below, the
  // flat base transmits what came through.
  float mu_in = mu0;
  if (sun_side) {
    // The top's slope: grad(top height) = thickness / density grad(tau),
    // in the layer's tangent plane (local x, y less their vertical part).
    const Eigen::Vector3f slope(gradient.x(), gradient.y(), 0.0f);
    const Eigen::Vector3f tangent = slope - c.up * c.up.dot(slope);
    const float k = static_cast<float>(o.thickness / o.density);
    const Eigen::Vector3f top = (c.up - k * tangent).normalized();
    // Half the tilt: light diffuses through a cloud's edge, so its lee side
    // is dimmer, not black.
    mu_in = std::clamp(0.5f * (mu0 + top.dot(light.sun_dir)), 0.02f, 1.0f);
  }
  // Self-shadowing: the sun's way in over the neighbouring columns.
  const float shadow = layer.sun_shadow(c.point, c.up, light.sun_dir, tau, footprint);
  const float r = slab_reflectance(tau, mu_in, g);
  const float t_diffuse = std::max(1.0f - r - std::exp(-scaled * tau / mu0), 0.0f);
  float sun = (sun_side ? r * mu_in : t_diffuse * mu0) / kPi;
  // The single scattering's departure from isotropic: bright rims towards
  // the sun, the phase function's shape on the cloud.
  const float cos_theta = dir.dot(light.sun_dir);  // 1: looking into the sun through it
  const float a = tau / mu, b = tau / mu0;
  sun += (cloud_phase(cos_theta) - 1.0f / (4.0f * kPi)) *
         single_scattering_geometry(tau / mu, a, b, sun_side);
  out.radiance += light.sun * (cover * shadow * std::max(sun, 0.0f));
  return out;
}

}  // namespace drift::render
