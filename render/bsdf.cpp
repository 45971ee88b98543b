#include "render/bsdf.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "render/brdf.h"
#include "render/sampling.h"

namespace drift::render {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

float luminance(const Eigen::Vector3f& c) {
  return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z();
}

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

// E(mu) at kTable cosines (mu = (i + 0.5) / kTable), by stratified sampling
// of the microfacet normals (Walter et al. 2007, eqs. 35-36 and 41), and its
// mean 2 int E(mu) mu dmu; computed once, deterministically.
constexpr int kTable = 64;
struct CoatTable {
  float e[kTable];
  float average = 0.0f;
  CoatTable() {
    const Eigen::Vector3f n(0, 0, 1);
    const int strata = 96;
    for (int i = 0; i < kTable; ++i) {
      const float mu = (static_cast<float>(i) + 0.5f) / kTable;
      const Eigen::Vector3f wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
      double sum = 0.0;
      for (int a = 0; a < strata; ++a) {
        for (int b = 0; b < strata; ++b) {
          const float u1 = (a + 0.5f) / strata, u2 = (b + 0.5f) / strata;
          const float tan2 = kWetCoatAlpha * kWetCoatAlpha * u1 / (1.0f - u1);
          const Eigen::Vector3f h =
              around(n, 1.0f / std::sqrt(1.0f + tan2), 2.0f * std::numbers::pi_v<float> * u2);
          const Eigen::Vector3f wi = 2.0f * wo.dot(h) * h - wo;
          if (wi.z() <= 0.0f) continue;
          // f cos_i / pdf with pdf = D cos_h / (4 |wo.h|).
          const float pdf = ggx_d(h.z(), kWetCoatAlpha) * h.z() / (4.0f * std::abs(wo.dot(h)));
          sum += coat_f(n, wi, wo) * wi.z() / pdf;
        }
      }
      e[i] = static_cast<float>(sum / (strata * strata));
      average += 2.0f * e[i] * mu / kTable;
    }
  }
};
const CoatTable& coat_table() {
  static const CoatTable table;
  return table;
}

float snow_single(const Eigen::Vector3f& n, const Eigen::Vector3f& wi, const Eigen::Vector3f& wo) {
  const float cos_i = n.dot(wi), cos_o = n.dot(wo);
  if (cos_i <= 0.0f || cos_o <= 0.0f) return 0.0f;
  // Light travels along -wi into the snow and leaves along wo.
  return henyey_greenstein(-wi.dot(wo), kSnowAsymmetry) / (cos_i + cos_o);
}

// R(mu) at kTable cosines by midpoint quadrature over (cos_i, phi): the lobe
// is smooth but forward-peaked, so 256 x 256 cells (error below 1e-4, checked
// against 4x the cells); and R_avg = 2 int R(mu) mu dmu.
struct SnowTable {
  float r[kTable];
  float average = 0.0f;
  SnowTable() {
    const Eigen::Vector3f n(0, 0, 1);
    constexpr int cells = 256;
    for (int i = 0; i < kTable; ++i) {
      const float mu = (static_cast<float>(i) + 0.5f) / kTable;
      const Eigen::Vector3f wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
      double sum = 0.0;
      for (int a = 0; a < cells; ++a) {
        const float cos_i = (a + 0.5f) / cells;
        for (int b = 0; b < cells; ++b) {
          const Eigen::Vector3f wi = around(n, cos_i, 2.0f * kPi * (b + 0.5f) / cells);
          // dw = dcos dphi; the integrand is f cos_i.
          sum += snow_single(n, wi, wo) * cos_i;
        }
      }
      r[i] = static_cast<float>(sum * 2.0 * std::numbers::pi / (cells * cells));
      average += 2.0f * r[i] * mu / kTable;
    }
  }
};
const SnowTable& snow_table() {
  static const SnowTable table;
  return table;
}

// Linear interpolation in a table of kTable values at cosines (i + 0.5) / kTable.
float lookup(const float* table, float cos_o) {
  const float x = std::clamp(cos_o, 0.0f, 1.0f) * kTable - 0.5f;
  const int i = std::clamp(static_cast<int>(std::floor(x)), 0, kTable - 2);
  const float f = std::clamp(x - static_cast<float>(i), 0.0f, 1.0f);
  return table[i] * (1.0f - f) + table[i + 1] * f;
}

}  // namespace

float coat_albedo(float cos_o) { return lookup(coat_table().e, cos_o); }

float coat_albedo_average() { return coat_table().average; }

float henyey_greenstein(float c, float g) {
  const float d = 1.0f + g * g - 2.0f * g * c;
  return (1.0f - g * g) / (4.0f * kPi * d * std::sqrt(d));
}

float snow_single_albedo(float cos_o) { return lookup(snow_table().r, cos_o); }

float snow_single_albedo_average() { return snow_table().average; }

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

float GroundBsdf::pdf(const Eigen::Vector3f& wi) const {
  const float cos_i = n_.dot(wi);
  if (cos_i <= 0.0f) return 0.0f;
  float p = (1.0f - p_spec_) * cos_i / kPi;
  if (p_spec_ > 0.0f) {
    // Walter et al. 2007, eqs. 14 and 38: p(wi) = D(h) cos_h / (4 |wo.h|).
    const Eigen::Vector3f h = (wi + wo_).normalized();
    const float wo_h = std::abs(wo_.dot(h));
    if (wo_h > 0.0f) p += p_spec_ * ggx_d(n_.dot(h), kWetCoatAlpha) * n_.dot(h) / (4.0f * wo_h);
  }
  return p;
}

bool GroundBsdf::sample(float u_lobe, float u1, float u2, Sample& s) const {
  if (p_spec_ <= 0.0f) {
    // Dry: cosine-weighted, so f cos / pdf = pi f: the albedo times the
    // Oren-Nayar factor, or with snow's lobe its share of pi f_snow.
    s.wi = cosine_sample(n_, u1, u2);
    s.pdf = std::max(n_.dot(s.wi), 0.0f) / kPi;
    s.weight = dry(s.wi, oren_nayar_factor(n_, s.wi, wo_, m_.roughness)) * kPi;
    return true;
  }
  if (u_lobe < p_spec_) {
    // A microfacet normal from D(h) cos_h (Walter et al. 2007, eqs. 35-36),
    // then the mirror direction about it.
    if (cos_o_ <= 0.0f) return false;
    const float tan2 = kWetCoatAlpha * kWetCoatAlpha * u1 / std::max(1.0f - u1, 1e-7f);
    const Eigen::Vector3f h =
        around(n_, 1.0f / std::sqrt(1.0f + tan2), 2.0f * std::numbers::pi_v<float> * u2);
    s.wi = 2.0f * wo_.dot(h) * h - wo_;
  } else {
    s.wi = cosine_sample(n_, u1, u2);
  }
  const float cos_i = n_.dot(s.wi);
  if (cos_i <= 0.0f) return false;
  s.pdf = pdf(s.wi);
  if (!(s.pdf > 0.0f)) return false;
  s.weight = eval(s.wi) * (cos_i / s.pdf);
  return true;
}

}  // namespace drift::render
