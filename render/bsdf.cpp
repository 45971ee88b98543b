#include "render/bsdf.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "render/color.h"
#include "render/oren_nayar.h"
#include "render/sampling.h"

namespace drift::render {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

constexpr float kF0 = fresnel_f0(kWaterIor);
// The film's hemispherical (cosine-weighted) reflectance from above with
// Schlick's Fresnel: 2 int F(mu) mu dmu = F0 + (1 - F0) / 21.
constexpr float kRe = kF0 + (1.0f - kF0) / 21.0f;
// ... and from below, total internal reflection included: what leaves is
// (1 - r_e) / n^2 of what arrives (Lekner & Dorf 1988).
constexpr float kRi = 1.0f - (1.0f - kRe) / (kWaterIor * kWaterIor);

float coat_f(const Eigen::Vector3f& n, const Eigen::Vector3f& wi, const Eigen::Vector3f& wo) {
  const float cos_i = n.dot(wi), cos_o = n.dot(wo);
  if (cos_i <= 0.0f || cos_o <= 0.0f) return 0.0f;
  const Eigen::Vector3f h = (wi + wo).normalized();
  return schlick_fresnel(wi.dot(h), kF0) * ggx_d(n.dot(h), kWetCoatAlpha) *
         ggx_g1(cos_i, kWetCoatAlpha) * ggx_g1(cos_o, kWetCoatAlpha) / (4.0f * cos_i * cos_o);
}

// A directional albedo E(mu), tabulated once at kTable view cosines
// mu = (i + 0.5) / kTable and looked up linearly, with its cosine-weighted
// mean 2 int E(mu) mu dmu.
constexpr int kTable = 64;
class AlbedoTable {
 public:
  // `albedo(wo)`: the integral int f(wi, wo) cos_i dwi for a view wo in the
  // x-z plane over the normal (0, 0, 1).
  template <class Fn>
  explicit AlbedoTable(Fn albedo) {
    for (int i = 0; i < kTable; ++i) {
      const float mu = (static_cast<float>(i) + 0.5f) / kTable;
      e_[i] = albedo(Eigen::Vector3f(std::sqrt(1.0f - mu * mu), 0.0f, mu));
      average_ += 2.0f * e_[i] * mu / kTable;
    }
  }
  float at(float cos_o) const {
    const float x = std::clamp(cos_o, 0.0f, 1.0f) * kTable - 0.5f;
    const int i = std::clamp(static_cast<int>(std::floor(x)), 0, kTable - 2);
    const float f = std::clamp(x - static_cast<float>(i), 0.0f, 1.0f);
    return e_[i] * (1.0f - f) + e_[i + 1] * f;
  }
  float average() const { return average_; }

 private:
  float e_[kTable] = {};
  float average_ = 0.0f;
};

// The sum of f(a, b) over the cells of an n x n grid, in order: the one loop
// of the tables' midpoint and stratified rules.
template <class F>
double grid_sum(int n, const F& f) {
  double sum = 0.0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) sum += f(a, b);
  return sum;
}

// The coat's E(mu) by stratified sampling of the microfacet normals (Walter
// et al. 2007, eqs. 35-36 and 41); computed once, deterministically.
const AlbedoTable& coat_table() {
  static const AlbedoTable table([](const Eigen::Vector3f& wo) {
    const Eigen::Vector3f n(0, 0, 1);
    constexpr int strata = 96;
    const double sum = grid_sum(strata, [&](int a, int b) {
      const float u1 = (a + 0.5f) / strata, u2 = (b + 0.5f) / strata;
      const float tan2 = kWetCoatAlpha * kWetCoatAlpha * u1 / (1.0f - u1);
      const Eigen::Vector3f h = around(n, 1.0f / std::sqrt(1.0f + tan2), 2.0f * kPi * u2);
      const Eigen::Vector3f wi = 2.0f * wo.dot(h) * h - wo;
      if (wi.z() <= 0.0f) return 0.0f;
      // f cos_i / pdf with pdf = D cos_h / (4 |wo.h|).
      const float pdf = ggx_d(h.z(), kWetCoatAlpha) * h.z() / (4.0f * std::abs(wo.dot(h)));
      return coat_f(n, wi, wo) * wi.z() / pdf;
    });
    return static_cast<float>(sum / (strata * strata));
  });
  return table;
}

float snow_single(const Eigen::Vector3f& n, const Eigen::Vector3f& wi, const Eigen::Vector3f& wo) {
  const float cos_i = n.dot(wi), cos_o = n.dot(wo);
  if (cos_i <= 0.0f || cos_o <= 0.0f) return 0.0f;
  // Light travels along -wi into the snow and leaves along wo.
  return henyey_greenstein(-wi.dot(wo), kSnowAsymmetry) / (cos_i + cos_o);
}

// Snow's single-scattering R(mu) by the midpoint rule over (cos_i, phi), fine
// enough for the forward peak at grazing views (the energy test of
// tests/render/bsdf_test.cpp holds to 3e-3).
const AlbedoTable& snow_table() {
  static const AlbedoTable table([](const Eigen::Vector3f& wo) {
    constexpr int cells = 256;
    // wi.wo = sin_i sin_o cos(phi) + cos_i cos_o for wo in the x-z plane:
    // the cosines of the cells' azimuths once, not a direction per cell.
    static const std::array<float, cells> cos_phi = [] {
      std::array<float, cells> c{};
      for (int b = 0; b < cells; ++b) c[b] = std::cos(2.0f * kPi * (b + 0.5f) / cells);
      return c;
    }();
    const float cos_o = wo.z(), sin_o = wo.x();
    const double sum = grid_sum(cells, [&](int a, int b) {
      const float cos_i = (a + 0.5f) / cells;
      const float sin_i = std::sqrt(1.0f - cos_i * cos_i);
      const float wi_wo = sin_i * sin_o * cos_phi[b] + cos_i * cos_o;
      // snow_single's value at this wi, times cos_i (dw = dcos dphi).
      return henyey_greenstein(-wi_wo, kSnowAsymmetry) / (cos_i + cos_o) * cos_i;
    });
    return static_cast<float>(sum * 2.0 * std::numbers::pi / (cells * cells));
  });
  return table;
}

}  // namespace

float coat_albedo(float cos_o) { return coat_table().at(cos_o); }

float coat_albedo_average() { return coat_table().average(); }

float henyey_greenstein(float c, float g) {
  const float d = 1.0f + g * g - 2.0f * g * c;
  return (1.0f - g * g) / (4.0f * kPi * d * std::sqrt(d));
}

float snow_single_albedo(float cos_o) { return snow_table().at(cos_o); }

float snow_single_albedo_average() { return snow_table().average(); }

float snow_reflectance(const Eigen::Vector3f& n, const Eigen::Vector3f& wi,
                       const Eigen::Vector3f& wo) {
  const float cos_i = n.dot(wi), cos_o = n.dot(wo);
  if (cos_i <= 0.0f || cos_o <= 0.0f) return 0.0f;
  const float multiple = (1.0f - snow_single_albedo(cos_i)) * (1.0f - snow_single_albedo(cos_o)) /
                         (kPi * (1.0f - snow_single_albedo_average()));
  return snow_single(n, wi, wo) + multiple;
}

float schlick_fresnel(float c, float f0) {
  const float m = std::clamp(1.0f - c, 0.0f, 1.0f);
  const float m2 = m * m;
  return f0 + (1.0f - f0) * m2 * m2 * m;
}

float ggx_d(float cos_h, float alpha) {
  if (cos_h <= 0.0f) return 0.0f;
  const float a2 = alpha * alpha;
  const float d = cos_h * cos_h * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * d * d);
}

float ggx_g1(float cos_v, float alpha) {
  if (cos_v <= 0.0f) return 0.0f;
  const float c2 = cos_v * cos_v;
  const float tan2 = std::max(0.0f, 1.0f - c2) / c2;
  return 2.0f / (1.0f + std::sqrt(1.0f + alpha * alpha * tan2));
}

Eigen::Vector3f wet_albedo(const Eigen::Vector3f& albedo) {
  return albedo.cwiseProduct(
      ((1.0f - kRi) * (Eigen::Vector3f::Ones() - albedo * kRi).cwiseInverse()));
}

GroundBsdf::GroundBsdf(const Eigen::Vector3f& n, const Eigen::Vector3f& wo,
                       const Material& material)
    : n_(n), wo_(wo), m_(material) {
  m_.wetness = std::clamp(m_.wetness, 0.0f, 1.0f);
  m_.forward_scattering = std::clamp(m_.forward_scattering, 0.0f, 1.0f);
  cos_o_ = n_.dot(wo_);
  // Snow's single scattering peaks where wi and wo face each other at grazing
  // angles (P(-wi.wo) / (cos_i + cos_o)): cosine sampling alone finds that
  // peak rarely and with huge weights, the grain of snow in low light. The
  // lobe is sampled in proportion to its share R(cos_o) of what snow
  // reflects towards wo, faded out between grazing views and cos_o = 0.5,
  // where the peak is mild and cosine samples do better (the lobe about -wo
  // then points mostly into the ground).
  if (m_.forward_scattering > 0.0f && cos_o_ > 0.0f) {
    const float grazing = std::clamp((0.5f - cos_o_) / 0.4f, 0.0f, 1.0f);
    p_fwd_ = std::min(0.75f, m_.forward_scattering * snow_single_albedo(cos_o_)) * grazing;
  }
  if (m_.wetness <= 0.0f) return;
  albedo_wet_ = wet_albedo(m_.albedo);
  const float e_o = coat_albedo(cos_o_);
  t_o_ = 1.0f - e_o;
  // Lobes in proportion to what they reflect towards wo, the coat at least a
  // quarter of the wet share so that glossy reflections of the sky converge.
  const float w = m_.wetness;
  const float ks = w * e_o;
  const float kd = (1.0f - w) * luminance(m_.albedo) + w * t_o_ * luminance(albedo_wet_);
  p_spec_ = std::min(0.9f, std::max(ks / std::max(ks + kd, 1e-6f), 0.25f * w));
}

Eigen::Vector3f GroundBsdf::eval(const Eigen::Vector3f& wi) const {
  const float cos_i = n_.dot(wi);
  if (cos_i <= 0.0f) return Eigen::Vector3f::Zero();
  const float on = oren_nayar_factor(n_, wi, wo_, m_.roughness);
  const float w = m_.wetness;
  Eigen::Vector3f f = dry(wi, on) * (1.0f - w);
  if (w <= 0.0f || cos_o_ <= 0.0f) return f;
  // Under the film: what the coat passes in and out (Kelemen & Szirmay-Kalos 2001).
  const float t_i = 1.0f - coat_albedo(cos_i);
  f += albedo_wet_ * (w * on / kPi * t_i * t_o_ / (1.0f - coat_albedo_average()));
  return f + Eigen::Vector3f::Constant(w * coat_f(n_, wi, wo_));
}

Eigen::Vector3f GroundBsdf::dry(const Eigen::Vector3f& wi, float on) const {
  const float s = m_.forward_scattering;
  if (s <= 0.0f) return m_.albedo * (on / kPi);
  return m_.albedo * ((1.0f - s) * on / kPi + s * snow_reflectance(n_, wi, wo_));
}

Eigen::Vector3f GroundBsdf::diffuse_sample(float u1, float u2) const {
  if (p_fwd_ <= 0.0f) return cosine_sample(n_, u1, u2);
  if (u1 >= p_fwd_) return cosine_sample(n_, (u1 - p_fwd_) / (1.0f - p_fwd_), u2);
  // Henyey-Greenstein about -wo by inversion of its cdf in the scattering
  // cosine c = -wi.wo (PBRT 3, eq. 15.14 in this sign convention).
  const float g = kSnowAsymmetry, u = u1 / p_fwd_;
  const float k = (1.0f - g * g) / (1.0f + g - 2.0f * g * u);
  const float c = std::clamp((1.0f + g * g - k * k) / (2.0f * g), -1.0f, 1.0f);
  return around(-wo_, c, 2.0f * kPi * u2);
}

float GroundBsdf::diffuse_pdf(const Eigen::Vector3f& wi, float cos_i) const {
  const float cosine = cos_i / kPi;
  if (p_fwd_ <= 0.0f) return cosine;
  return (1.0f - p_fwd_) * cosine + p_fwd_ * henyey_greenstein(-wi.dot(wo_), kSnowAsymmetry);
}

float GroundBsdf::pdf(const Eigen::Vector3f& wi) const {
  const float cos_i = n_.dot(wi);
  if (cos_i <= 0.0f) return 0.0f;
  float p = (1.0f - p_spec_) * diffuse_pdf(wi, cos_i);
  if (p_spec_ > 0.0f) {
    // Walter et al. 2007, eqs. 14 and 38: p(wi) = D(h) cos_h / (4 |wo.h|).
    const Eigen::Vector3f h = (wi + wo_).normalized();
    const float wo_h = std::abs(wo_.dot(h));
    if (wo_h > 0.0f) p += p_spec_ * ggx_d(n_.dot(h), kWetCoatAlpha) * n_.dot(h) / (4.0f * wo_h);
  }
  return p;
}

bool GroundBsdf::sample(float u_lobe, float u1, float u2, Sample& s) const {
  if (p_spec_ <= 0.0f && p_fwd_ <= 0.0f) {
    // Dry: cosine-weighted, so f cos / pdf = pi f: the albedo times the
    // Oren-Nayar factor.
    s.wi = cosine_sample(n_, u1, u2);
    s.pdf = std::max(n_.dot(s.wi), 0.0f) / kPi;
    s.weight = dry(s.wi, oren_nayar_factor(n_, s.wi, wo_, m_.roughness)) * kPi;
    return true;
  }
  if (p_spec_ > 0.0f && u_lobe < p_spec_) {
    // A microfacet normal from D(h) cos_h (Walter et al. 2007, eqs. 35-36),
    // then the mirror direction about it.
    if (cos_o_ <= 0.0f) return false;
    const float tan2 = kWetCoatAlpha * kWetCoatAlpha * u1 / std::max(1.0f - u1, 1e-7f);
    const Eigen::Vector3f h =
        around(n_, 1.0f / std::sqrt(1.0f + tan2), 2.0f * std::numbers::pi_v<float> * u2);
    s.wi = 2.0f * wo_.dot(h) * h - wo_;
  } else {
    s.wi = diffuse_sample(u1, u2);
  }
  const float cos_i = n_.dot(s.wi);
  if (cos_i <= 0.0f) return false;
  s.pdf = pdf(s.wi);
  if (!(s.pdf > 0.0f)) return false;
  s.weight = eval(s.wi) * (cos_i / s.pdf);
  return true;
}

}  // namespace drift::render
