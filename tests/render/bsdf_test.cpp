// The wet-ground BSDF against its invariants: reciprocity, energy at most 1 at
// every view angle, the dry case exactly Lambert/Oren-Nayar, samples and pdf
// consistent with the function, and Lekner & Dorf's darkening.
#include "render/bsdf.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "render/random.h"

using namespace drift::render;
using Eigen::Vector3f;

namespace {

constexpr float kPi = std::numbers::pi_v<float>;
const Vector3f kUp(0, 0, 1);

Vector3f view(float cos_o) {
  return Vector3f(std::sqrt(1.0f - cos_o * cos_o), 0.0f, cos_o).normalized();
}

// Directional albedo int f cos dwi by the BSDF's own sampling: the mean weight.
Vector3f albedo_by_sampling(const GroundBsdf& bsdf, int n) {
  Eigen::Vector3d sum(0, 0, 0);
  for (int i = 0; i < n; ++i) {
    SampleStream rng(7, 0, static_cast<std::uint64_t>(i));
    const float u = rng.next1d();
    const auto [u1, u2] = rng.next2d();
    GroundBsdf::Sample s;
    if (bsdf.sample(u, u1, u2, s)) sum += s.weight.cast<double>();
  }
  return (sum / n).cast<float>();
}

// The same integral by a fine midpoint rule over the hemisphere, and the
// integral of the pdf.
void quadrature(const GroundBsdf& bsdf, double& albedo, double& pdf_mass) {
  const int nt = 1500, np = 600;
  albedo = pdf_mass = 0.0;
  for (int i = 0; i < nt; ++i) {
    const double t = (i + 0.5) / nt * std::numbers::pi / 2;
    for (int j = 0; j < np; ++j) {
      const double p = (j + 0.5) / np * 2 * std::numbers::pi;
      const Vector3f wi(static_cast<float>(std::sin(t) * std::cos(p)),
                        static_cast<float>(std::sin(t) * std::sin(p)),
                        static_cast<float>(std::cos(t)));
      const double dw = std::sin(t) * (std::numbers::pi / 2 / nt) * (2 * std::numbers::pi / np);
      albedo += bsdf.eval(wi).x() * std::cos(t) * dw;
      pdf_mass += bsdf.pdf(wi) * dw;
    }
  }
}

}  // namespace

TEST(WetBsdf, DryIsLambertTimesOrenNayar) {
  const Material dry{{0.4f, 0.3f, 0.2f}, 0.0f, 0.0f};
  const GroundBsdf bsdf(kUp, view(0.6f), dry);
  const Vector3f wi = Vector3f(0.3f, -0.2f, 0.9f).normalized();
  EXPECT_NEAR((bsdf.eval(wi) - dry.albedo / kPi).norm(), 0.0f, 1e-7f);
  EXPECT_FLOAT_EQ(bsdf.pdf(wi), wi.z() / kPi);
  EXPECT_EQ(bsdf.specular_probability(), 0.0f);
  GroundBsdf::Sample s;
  ASSERT_TRUE(bsdf.sample(0.0f, 0.3f, 0.7f, s));
  EXPECT_EQ(s.weight, dry.albedo);  // cosine sampling: f cos / pdf is the albedo
}

TEST(WetBsdf, Reciprocal) {
  const Material wet{{0.3f, 0.25f, 0.2f}, 0.3f, 0.7f};
  const Vector3f a = Vector3f(0.5f, 0.1f, 0.6f).normalized();
  const Vector3f b = Vector3f(-0.45f, -0.05f, 0.7f).normalized();  // near the mirror of a
  const Vector3f fab = GroundBsdf(kUp, b, wet).eval(a), fba = GroundBsdf(kUp, a, wet).eval(b);
  EXPECT_NEAR((fab - fba).norm(), 0.0f, 1e-5f * fab.norm())
      << fab.transpose() << " vs " << fba.transpose();
}

TEST(WetBsdf, ReflectsAtMostOneAtEveryViewAngle) {
  // A white ground under a water film: what the coat does not reflect the
  // ground returns (A_wet = 1), so the directional albedo is 1 at every angle
  // (up to the coat table's interpolation).
  for (float wetness : {0.5f, 1.0f}) {
    for (float cos_o : {1.0f, 0.8f, 0.707f, 0.5f, 0.25f, 0.1f, 0.03f}) {
      const GroundBsdf bsdf(kUp, view(cos_o), {{1, 1, 1}, 0.0f, wetness});
      double albedo, mass;
      quadrature(bsdf, albedo, mass);
      const Vector3f sampled = albedo_by_sampling(bsdf, 200000);
      std::printf("wetness %.1f cos_o %.3f: albedo %.5f (sampled %.5f), pdf mass %.4f\n", wetness,
                  cos_o, albedo, sampled.x(), mass);
      EXPECT_LE(albedo, 1.0 + 2e-3) << "wetness " << wetness << " cos_o " << cos_o;
      EXPECT_GT(albedo, 0.98) << "wetness " << wetness << " cos_o " << cos_o;
      // Sampling and pdf agree with the function (MC error ~0.3 %; the
      // quadrature resolves the coat's lobe to ~0.1 %).
      EXPECT_NEAR(sampled.x(), albedo, 0.01 * albedo)
          << "wetness " << wetness << " cos_o " << cos_o;
      // Coat samples below the horizon are lost, so the pdf's mass is <= 1.
      EXPECT_LE(mass, 1.0 + 2e-3);
      EXPECT_GT(mass, 0.5);
    }
  }
}

TEST(WetBsdf, CoatAlbedoTable) {
  // Head-on the coat reflects Fresnel's 2 %; its mean is close to Schlick's
  // hemispherical r_e = F0 + (1 - F0) / 21 = 0.067, less what masking loses.
  EXPECT_NEAR(coat_albedo(1.0f), 0.02f, 2e-3f);
  EXPECT_GT(coat_albedo(0.05f), coat_albedo(0.5f));
  EXPECT_LE(coat_albedo(0.0f), 1.0f);
  EXPECT_NEAR(coat_albedo_average(), 0.06f, 0.015f);
  std::printf("coat albedo: E(1) %.4f, E(0.5) %.4f, E(0.1) %.4f, E(0.02) %.4f, mean %.4f\n",
              coat_albedo(1.0f), coat_albedo(0.5f), coat_albedo(0.1f), coat_albedo(0.02f),
              coat_albedo_average());
}

TEST(WetBsdf, WaterDarkensDarkGroundMost) {
  // Lekner & Dorf 1988: A_wet = A (1 - r_i) / (1 - A r_i), r_i ~ 0.47 for water.
  EXPECT_NEAR(wet_albedo({1, 1, 1}).x(), 1.0f, 1e-6f);
  const float sand = wet_albedo(Vector3f::Constant(0.38f)).x() / 0.38f;
  const float soil = wet_albedo(Vector3f::Constant(0.1f)).x() / 0.1f;
  EXPECT_NEAR(sand, 0.643f, 0.01f);
  EXPECT_LT(soil, sand);
  // Fresnel: water reflects 2 % at normal incidence, all at grazing.
  EXPECT_NEAR(fresnel_f0(kWaterIor), 0.0201f, 1e-4f);
  EXPECT_FLOAT_EQ(schlick_fresnel(0.0f, 0.02f), 1.0f);
}

TEST(WetBsdf, GgxNormalsIntegrateToOne) {
  // int D(h) cos_h dh = 1 over the hemisphere (Walter et al. 2007, eq. 4).
  for (float alpha : {0.05f, 0.12f, 0.5f}) {
    const int n = 200000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      // cos_h uniform in [0, 1] is uniform in solid angle over a hemisphere / 2 pi.
      const float c = (static_cast<float>(i) + 0.5f) / n;
      sum += ggx_d(c, alpha) * c * 2.0 * std::numbers::pi / n;
    }
    EXPECT_NEAR(sum, 1.0, 2e-3) << "alpha " << alpha;
  }
}

TEST(SnowBsdf, PhaseFunctionIntegratesToOneWithItsAsymmetry) {
  // int P dw = 1 and int P cos dw = g (Henyey & Greenstein 1941).
  double mass = 0.0, mean_cos = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double c = -1.0 + 2.0 * (i + 0.5) / n;
    const double p = henyey_greenstein(static_cast<float>(c), kSnowAsymmetry);
    mass += p * 2.0 * std::numbers::pi * 2.0 / n;
    mean_cos += p * c * 2.0 * std::numbers::pi * 2.0 / n;
  }
  EXPECT_NEAR(mass, 1.0, 1e-3);
  EXPECT_NEAR(mean_cos, kSnowAsymmetry, 2e-3);
}

TEST(SnowBsdf, ReciprocalAndReflectsExactlyItsAlbedoAtEveryAngle) {
  const Material snow{{0.9f, 0.92f, 0.95f}, 0.0f, 0.0f, 1.0f};
  const Vector3f a = Vector3f(0.8f, 0.1f, 0.3f).normalized();
  const Vector3f b = Vector3f(-0.7f, 0.2f, 0.4f).normalized();
  const Vector3f fab = GroundBsdf(kUp, b, snow).eval(a), fba = GroundBsdf(kUp, a, snow).eval(b);
  EXPECT_NEAR((fab - fba).norm(), 0.0f, 1e-6f * fab.norm());
  // Energy: for a white snow the directional albedo is 1 at every view angle
  // (the coupled multiple-scattering term returns what single scattering
  // does not), by quadrature and by the sampler.
  const Material white{{1, 1, 1}, 0.0f, 0.0f, 1.0f};
  for (float cos_o : {0.05f, 0.2f, 0.5f, 0.8f, 1.0f}) {
    const GroundBsdf bsdf(kUp, view(cos_o), white);
    double albedo = 0.0, pdf_mass = 0.0;
    quadrature(bsdf, albedo, pdf_mass);
    EXPECT_NEAR(albedo, 1.0, 3e-3) << "cos_o " << cos_o;
    // The density over the hemisphere: 1 less the forward lobe's samples
    // that fall below the surface (no direction; the estimate stays unbiased).
    EXPECT_LE(pdf_mass, 1.0 + 3e-3) << "cos_o " << cos_o;
    EXPECT_GE(pdf_mass, 1.0 - bsdf.forward_probability() - 3e-3) << "cos_o " << cos_o;
    // Sampled with its forward lobe, the estimate is within 0.5 % (cosine
    // sampling alone needed 2.5 % at grazing views: the peak seen as noise).
    EXPECT_NEAR(albedo_by_sampling(bsdf, 200000).x(), 1.0f, 5e-3f) << "cos_o " << cos_o;
  }
}

TEST(SnowBsdf, ForwardLobeSamplingKeepsTheWeightsSmallAtGrazingViews) {
  // The grain of snow in low light: at a grazing view a cosine sample that
  // finds the forward peak carries pi f of tens. With the lobe sampled too,
  // f cos / pdf stays bounded (A s / p_fwd at the peak): the weights' relative
  // spread is what a pixel's noise grows with.
  const Material white{{1, 1, 1}, 0.0f, 0.0f, 1.0f};
  for (float cos_o : {0.05f, 0.15f}) {
    const GroundBsdf bsdf(kUp, view(cos_o), white);
    EXPECT_GT(bsdf.forward_probability(), 0.05f);
    double sum = 0.0, sum2 = 0.0, most = 0.0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
      SampleStream rng(11, 0, static_cast<std::uint64_t>(i));
      const float u = rng.next1d();
      const auto [u1, u2] = rng.next2d();
      GroundBsdf::Sample s;
      const double w = bsdf.sample(u, u1, u2, s) ? s.weight.x() : 0.0;
      sum += w;
      sum2 += w * w;
      most = std::max(most, w);
    }
    const double mean = sum / n, spread = std::sqrt(std::max(sum2 / n - mean * mean, 0.0)) / mean;
    std::printf("cos_o %.2f: mean weight %.4f, relative spread %.3f, largest %.2f\n", cos_o, mean,
                spread, most);
    EXPECT_LT(spread, 1.0) << "cos_o " << cos_o;
    EXPECT_LT(most, 6.0) << "cos_o " << cos_o;
  }
  // Other materials keep plain cosine sampling (same samples, same bits).
  EXPECT_EQ(GroundBsdf(kUp, view(0.05f), *material_preset("rock")).forward_probability(), 0.0f);
}

TEST(SnowBsdf, ForwardScatteringGlintsAgainstALowSun) {
  // Sun and view 80 degrees from the zenith: facing each other (forward
  // scattering) snow reflects well above a Lambertian surface of its albedo,
  // with the sun behind the viewer far less; seen from overhead under an
  // overhead sun, about Lambert.
  const float s80 = std::sin(80.0f * kPi / 180.0f), c80 = std::cos(80.0f * kPi / 180.0f);
  const Vector3f sun(s80, 0.0f, c80);
  const Material snow = *material_preset("snow");
  auto factor = [&](const Vector3f& wo, const Vector3f& wi) {
    // Reflectance factor: f relative to the Lambertian A / pi.
    return GroundBsdf(kUp, wo, snow).eval(wi).x() * kPi / snow.albedo.x();
  };
  const float forward = factor(Vector3f(-s80, 0.0f, c80), sun);
  const float backward = factor(sun, sun);
  const float overhead = factor(kUp, kUp);
  std::printf("reflectance factor: forward %.3f, backward %.3f, overhead %.3f\n", forward, backward,
              overhead);
  EXPECT_GT(forward, 1.5f);
  EXPECT_LT(forward, 3.0f);
  EXPECT_LT(backward, 0.5f * forward);
  EXPECT_NEAR(overhead, 1.0f, 0.2f);
  // A plain material has no glint.
  const Material rock = *material_preset("rock");
  EXPECT_NEAR(GroundBsdf(kUp, Vector3f(-s80, 0.0f, c80), rock).eval(sun).x(),
              GroundBsdf(kUp, sun, rock).eval(Vector3f(-s80, 0.0f, c80)).x(), 1e-6f);
}
