// The sky's importance sampling: the tabulated density is a density and the
// one sample() draws from, the estimator of the sky's integral is unbiased,
// and in the path tracer multiple importance sampling gives the same ground
// as brute-force cosine sampling with less noise.
#include "render/sky_sampler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "render/random.h"
#include "render/renderer.h"
#include "render/terrain_scene.h"

using namespace drift::render;
using Eigen::Vector3f;

namespace {

constexpr double kPi = std::numbers::pi;

// A sky with a bright disc-like glow around (1, 0, 1)/sqrt 2 over a dim dome,
// dark below the horizon.
Vector3f glow_sky(const Vector3f& d) {
  const Vector3f sun = Vector3f(1, 0, 1).normalized();
  const float glow = 20.0f * std::exp(-40.0f * (1.0f - d.dot(sun)));
  const float dome = d.z() > 0 ? 0.3f + 0.2f * d.z() : 0.05f;
  return Vector3f(dome + glow, dome + 0.8f * glow, dome + 0.5f * glow);
}

float luminance(const Vector3f& c) { return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z(); }

// Integral over the sphere of g(direction) by a fine midpoint rule.
template <class G>
double sphere_integral(G g) {
  const int nt = 800, np = 1600;
  double sum = 0.0;
  for (int i = 0; i < nt; ++i) {
    const double t = (i + 0.5) / nt * kPi;
    for (int j = 0; j < np; ++j) {
      const double p = (j + 0.5) / np * 2 * kPi;
      const Vector3f d(static_cast<float>(std::sin(t) * std::cos(p)),
                       static_cast<float>(std::sin(t) * std::sin(p)),
                       static_cast<float>(std::cos(t)));
      sum += g(d) * std::sin(t) * (kPi / nt) * (2 * kPi / np);
    }
  }
  return sum;
}

}  // namespace

TEST(Distribution1D, GuidedSearchFindsTheCellOfAFullSearch) {
  // 128 cells with runs of zeros: the guide table's search returns the cell
  // whose cdf interval holds u (the first of a run of equal entries), as a
  // search of the whole table does, including u at the cells' edges.
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> v(0.0f, 1.0f);
  std::vector<float> f(128);
  for (float& x : f) x = v(rng) < 0.3f ? 0.0f : v(rng) * v(rng) * 10.0f;
  const Distribution1D d(f);
  std::vector<float> cdf(f.size() + 1, 0.0f);  // as the constructor sums it
  for (std::size_t i = 0; i < f.size(); ++i) cdf[i + 1] = cdf[i] + f[i] / 128.0f;
  for (float& c : cdf) c /= cdf.back();
  std::vector<float> us;
  for (int k = 0; k < 20000; ++k) us.push_back(v(rng));
  for (float c : cdf) us.push_back(std::min(c, 0.99999994f));
  for (float u : us) {
    float pdf = 0.0f;
    int cell = -1;
    d.sample(u, pdf, cell);
    const int full = std::clamp(
        static_cast<int>(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()) - 1, 0, 127);
    ASSERT_EQ(cell, full) << u;
    ASSERT_GT(f[cell], 0.0f) << u;
  }
}

TEST(Distribution1D, SamplesFollowTheFunction) {
  const Distribution1D d({1.0f, 0.0f, 3.0f, 0.0f});
  EXPECT_FLOAT_EQ(d.integral(), 1.0f);
  EXPECT_FLOAT_EQ(d.pdf(2), 3.0f);
  float pdf;
  int cell;
  EXPECT_NEAR(d.sample(0.125f, pdf, cell), 0.125f,
              1e-6f);  // half way through cell 0's mass
  EXPECT_EQ(cell, 0);
  EXPECT_NEAR(d.sample(0.625f, pdf, cell), 0.625f, 1e-6f);
  EXPECT_EQ(cell, 2);
  EXPECT_FLOAT_EQ(pdf, 3.0f);
  d.sample(0.25f, pdf, cell);  // never a cell of zero density
  EXPECT_EQ(cell, 2);
}

TEST(SkySampler, PdfIsADensityAndMatchesItsSamples) {
  const SkySampler sampler(glow_sky);
  EXPECT_NEAR(sphere_integral([&](const Vector3f& d) { return sampler.pdf(d); }), 1.0, 2e-3);
  for (int i = 0; i < 1000; ++i) {
    SampleStream rng(3, 0, static_cast<std::uint64_t>(i));
    const auto [u1, u2] = rng.next2d();
    SkySampler::Sample s;
    ASSERT_TRUE(sampler.sample(u1, u2, s));
    EXPECT_NEAR(s.dir.norm(), 1.0f, 1e-5f);
    EXPECT_NEAR(s.pdf, sampler.pdf(s.dir), 1e-3f * s.pdf) << "sample " << i;
  }
  // A black sky has nothing to sample.
  SkySampler::Sample s;
  EXPECT_FALSE(SkySampler([](const Vector3f&) { return Vector3f(0, 0, 0); }).sample(0.5f, 0.5f, s));
}

TEST(SkySampler, EstimatesTheSkysIntegralWithLowVariance) {
  // int L dw by importance sampling vs the quadrature; the relative variance
  // per sample is far below uniform sampling's.
  const SkySampler sampler(glow_sky);
  const double exact = sphere_integral([](const Vector3f& d) { return luminance(glow_sky(d)); });
  const int n = 100000;
  double sum = 0, sum2 = 0, usum = 0, usum2 = 0;
  for (int i = 0; i < n; ++i) {
    SampleStream rng(5, 0, static_cast<std::uint64_t>(i));
    const auto [u1, u2] = rng.next2d();
    SkySampler::Sample s;
    ASSERT_TRUE(sampler.sample(u1, u2, s));
    const double x = luminance(glow_sky(s.dir)) / s.pdf;
    sum += x, sum2 += x * x;
    // Uniform on the sphere, for comparison.
    const float z = 1.0f - 2.0f * u1, r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const Vector3f d(r * std::cos(2.0f * static_cast<float>(kPi) * u2),
                     r * std::sin(2.0f * static_cast<float>(kPi) * u2), z);
    const double y = luminance(glow_sky(d)) * 4.0 * kPi;
    usum += y, usum2 += y * y;
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  const double umean = usum / n, uvar = usum2 / n - umean * umean;
  std::printf(
      "sky integral %.5f: importance %.5f (variance %.4g), uniform "
      "%.5f (variance %.4g)\n",
      exact, mean, var, umean, uvar);
  EXPECT_NEAR(mean, exact, 3.0 * std::sqrt(var / n) + 1e-3 * exact);
  EXPECT_LT(var, 0.1 * uvar);
}

namespace {

// A flat plane seen straight down under the physical sky: every pixel sees
// the same irradiance, so the spread over pixels is the per-pixel noise.
struct PlaneUnderSky {
  SceneInput in;
  std::unique_ptr<TerrainScene> scene;
  Camera camera;
  PlaneUnderSky() {
    drift::terrain::HeightField dem(64, 64, 1500.0f, drift::terrain::local_georeference(100.0));
    in.terrain = dem;
    in.surface.ground = {{0.5f, 0.5f, 0.5f}, 0.0f, 0.0f};
    in.sun.elevation_deg = 12.0;  // a low sun: a bright aureole and a reddened sky
    in.sun.irradiance = 3.0;
    scene = std::make_unique<TerrainScene>(in);
    camera.from = scene->origin() + Eigen::Vector3d(0, 0, 50);
    camera.to = scene->origin() + Eigen::Vector3d(0, 0.001, 0);
    camera.vertical_fov_deg = 20.0;
  }
  // Mean and variance over the pixels of the luminance.
  void render(bool sample_sky, int spp, int size, double& mean, double& var) const {
    RenderSettings rs;
    rs.width = rs.height = size;
    rs.samples_per_pixel = spp;
    rs.max_depth = 1;
    rs.sample_sky = sample_sky;
    const Image img = render_image(*scene, in, camera, rs);
    double s = 0, s2 = 0;
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        const double l = luminance({img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2)});
        s += l, s2 += l * l;
      }
    }
    const double n = static_cast<double>(size) * size;
    mean = s / n;
    var = s2 / n - mean * mean;
  }
};

}  // namespace

TEST(SkySampler, MisOnAPlaneAgreesWithBruteForceWithLessNoise) {
  const PlaneUnderSky plane;
  double brute, brute_var, mis, mis_var;
  plane.render(false, 64, 64, brute, brute_var);  // 262144 cosine-sampled paths
  plane.render(true, 64, 64, mis, mis_var);
  double brute1, brute1_var, mis1, mis1_var;  // one sample per pixel: the noise
  plane.render(false, 1, 64, brute1, brute1_var);
  plane.render(true, 1, 64, mis1, mis1_var);
  std::printf(
      "plane under the sky: brute force %.5f, MIS %.5f (%.3f %%); "
      "variance per sample "
      "brute %.4g, MIS %.4g (x%.2f)\n",
      brute, mis, 100.0 * (mis - brute) / brute, brute1_var, mis1_var, brute1_var / mis1_var);
  // Standard errors of the means are ~0.1 %; allow 0.5 %.
  EXPECT_NEAR(mis, brute, 5e-3 * brute);
  // The sky's samples all above the horizon (render/path_tracer.cpp): a
  // sixth of brute force's variance (x5.9); a third (x3.0) when the sampler
  // spent 57-68 % of its samples below the horizon, where the plane is.
  EXPECT_LT(mis1_var, 0.25 * brute1_var);
}
