// The cloud layer (render/clouds.h): its coverage is the asked fraction, its
// footprint filter keeps the mean, its slab optics have the right limits,
// its shadow darkens the ground under cloud and nowhere else, it appears in
// the sky seen by rays, and a render with clouds is the same bits whatever
// the thread count.
#include "render/clouds.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <numbers>
#include <random>

#include "render/renderer.h"
#include "render/terrain_scene.h"
#include "terrain/error.h"
#include "tests/dem_fixture.h"

namespace drift::render {
namespace {

CloudOptions options(double coverage, std::uint64_t seed = 3) {
  CloudOptions o;
  o.enabled = true;
  o.coverage = coverage;
  o.seed = seed;
  return o;
}

// Fraction of n random points (far from where the threshold was measured)
// under cloud, at full detail.
double covered_fraction(const CloudLayer& layer, int n) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(2e5, 6e5);
  int covered = 0;
  for (int i = 0; i < n; ++i) covered += layer.optical_depth(u(rng), u(rng), 0.0) > 0.0f;
  return static_cast<double>(covered) / n;
}

TEST(Clouds, CoveredFractionIsTheCoverage) {
  for (const double c : {0.0, 0.1, 0.35, 0.7, 1.0}) {
    const CloudLayer layer(options(c), {0, 0, 0});
    EXPECT_NEAR(covered_fraction(layer, 40000), c, 0.025) << "coverage " << c;
  }
  // Another seed: other clouds, the same fraction.
  EXPECT_NEAR(covered_fraction(CloudLayer(options(0.35, 77), {0, 0, 0}), 40000), 0.35, 0.025);
}

TEST(Clouds, FootprintFilterKeepsTheMean) {
  // Far cloud (a footprint of a fifth of the largest wavelength) drops most
  // octaves; its optical depth must still average what point samples of the
  // full field average over the same area, at the pixel scale: each filtered
  // value against the mean of 64 full-detail samples inside its footprint.
  const CloudLayer layer(options(0.4), {1e4, -3e4, 0});
  const double footprint = 500.0;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1e5), d(-0.5, 0.5);
  double sum_filtered = 0, sum_box = 0, err2 = 0, spread2 = 0;
  const int centres = 400, inside = 64;
  for (int i = 0; i < centres; ++i) {
    const double x = u(rng), y = u(rng);
    double box = 0;
    for (int k = 0; k < inside; ++k)
      box += layer.optical_depth(x + footprint * d(rng), y + footprint * d(rng), 0.0);
    box /= inside;
    const double filtered = layer.optical_depth(x, y, footprint);
    const double point = layer.optical_depth(x, y, 0.0);
    sum_filtered += filtered, sum_box += box;
    err2 += (filtered - box) * (filtered - box);
    spread2 += (point - box) * (point - box);
  }
  EXPECT_NEAR(sum_filtered / centres, sum_box / centres, 0.08 * sum_box / centres);
  // The filtered value is closer to the footprint's mean than a point sample
  // (which aliases): the rms error at most 75 % of the point sample's (64 %
  // measured).
  std::printf("rms error against the footprint's mean: filtered %.3f, point %.3f\n",
              std::sqrt(err2 / centres), std::sqrt(spread2 / centres));
  EXPECT_LT(std::sqrt(err2 / centres), 0.75 * std::sqrt(spread2 / centres));
}

TEST(Clouds, SlabOpticsLimits) {
  // The phase function integrates to 1 over the sphere.
  double integral = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double mu = -1.0 + 2.0 * (i + 0.5) / n;
    integral += cloud_phase(static_cast<float>(mu)) * 2.0 * std::numbers::pi * (2.0 / n);
  }
  EXPECT_NEAR(integral, 1.0, 2e-3);
  const float g = cloud_asymmetry();
  EXPECT_GT(g, 0.6f);  // water clouds scatter forward
  // No slab reflects nothing; a thick one reflects almost all (no absorption);
  // more cloud reflects more.
  EXPECT_FLOAT_EQ(slab_reflectance(0.0f, 0.7f, g), 0.0f);
  EXPECT_GT(slab_reflectance(1000.0f, 0.7f, g), 0.95f);
  float last = 0.0f;
  for (const float tau : {0.5f, 2.0f, 8.0f, 32.0f}) {
    const float r = slab_reflectance(tau, 0.7f, g);
    EXPECT_GT(r, last) << tau;
    last = r;
  }
}

TEST(Clouds, RaysCrossTheLayerOnceFromBelowAndMissItAboveTheHorizonFromAbove) {
  const CloudLayer layer(options(0.5), {0, 0, 1000});  // local z 0 is 1000 m up
  CloudCrossing c;
  ASSERT_TRUE(layer.cross({0, 0, 0}, {0, 0, 1}, 1e30f, c));
  EXPECT_NEAR(c.distance, 4500.0f - 1000.0f, 0.5f);
  EXPECT_FALSE(layer.cross({0, 0, 0}, {0, 0, 1}, 3000.0f, c)) << "beyond max_distance";
  EXPECT_FALSE(layer.cross({0, 0, 6000}, {0, 0, 1}, 1e30f, c)) << "above it, looking up";
  ASSERT_TRUE(layer.cross({0, 0, 6000}, {0, 0, -1}, 1e30f, c));
  EXPECT_NEAR(c.distance, 6000.0f + 1000.0f - 4500.0f, 0.5f);
  // A horizontal ray from below meets the curved layer far away, never
  // further than the horizon distance.
  ASSERT_TRUE(layer.cross({0, 0, 0}, {1, 0, 0}, 1e30f, c));
  EXPECT_GT(c.distance, 1e5f);
  EXPECT_LE(c.distance, layer.horizon_distance(0.0) * 1.001);
}

// Flat ground of albedo 0.5 under a clear physical sky, sun overhead, seen
// from 300 m straight down; clouds 1 km up with small features so the frame
// holds both cloud shadow and open ground.
struct ShadowScene {
  SceneInput in;
  CloudOptions clouds;
  ShadowScene() {
    in.terrain = testing::dem_from(64, 10.0, 0.5, [](double, double) { return 0.0; });
    in.surface.ground.albedo = {0.5f, 0.5f, 0.5f};
    in.sun.elevation_deg = 90.0;
    in.sun.color = {1, 1, 1};
    in.sky.haze = 0.0f;
    clouds = options(0.5, 11);
    clouds.altitude = 1000.0;
    clouds.scale = 100.0;
    clouds.density = 12.0;
  }
};

Camera looking_down(const TerrainScene& scene) {
  Camera c;
  c.from = scene.origin() + Eigen::Vector3d(0, 0, 300);
  c.to = scene.origin() + Eigen::Vector3d(0, 0.001, 0);
  c.vertical_fov_deg = 70.0;
  return c;
}

TEST(Clouds, ShadowDarkensTheGroundUnderCloudAndNowhereElse) {
  ShadowScene s;
  const TerrainScene scene(s.in);
  RenderSettings rs;
  rs.width = rs.height = 32;
  rs.samples_per_pixel = 16;
  rs.max_depth = 1;
  const Camera cam = looking_down(scene);
  const Image clear = render_image(scene, s.in, cam, rs);
  s.in.clouds = s.clouds;
  const Image cloudy = render_image(scene, s.in, cam, rs);
  // Each pixel's ground point and the optical depth straight above it (the
  // sun is overhead, so that is where its shadow ray crosses the layer).
  const CloudLayer layer(s.clouds, scene.origin());
  const CameraRays rays = make_camera_rays(scene, cam, rs.width, rs.height);
  // Per pixel: clear, and the change clouds make.
  double open_clear = 0, open_change = 0, shade_change = 0;
  int open = 0, shade = 0;
  for (int y = 0; y < rs.height; ++y) {
    for (int x = 0; x < rs.width; ++x) {
      Eigen::Vector3f o, d;
      rays.ray(x + 0.5f, y + 0.5f, 0.0f, 0.0f, o, d);
      Hit hit;
      ASSERT_TRUE(scene.intersect(o, d, hit));
      // Away from edges: the pixel's ground and the sun's penumbra (10 m).
      const float tau = layer.optical_depth(hit.position.x(), hit.position.y(), 40.0);
      const double change = cloudy.at(x, y, 1) - clear.at(x, y, 1);
      if (tau < 0.01f * s.clouds.density)
        open_clear += clear.at(x, y, 1), open_change += change, ++open;
      if (tau > 0.8f * s.clouds.density) shade_change += change, ++shade;
    }
  }
  ASSERT_GT(open, 20);
  ASSERT_GT(shade, 20);
  open_clear /= open, open_change /= open, shade_change /= shade;
  // Open ground keeps its sun: never darker; it gains the clouds' diffuse
  // light (the sky above it is partly bright cloud instead of blue), as
  // broken cumulus do brighten open ground.
  EXPECT_GT(open_change / open_clear, -0.02);
  // Ground in shadow loses, besides, the direct sun: its share of the clear
  // light (sun overhead in clean air: ~85-90 %) times 1 - T, T = exp(-(1 - g^2)
  // tau) < 7 % for tau > 0.8 x 12. The clouds' diffuse light is the same on
  // both (cloud 1 km up, points 100 m apart).
  const double lost = (open_change - shade_change) / open_clear;
  EXPECT_GT(lost, 0.7);
  EXPECT_LT(lost, 1.0);
  std::printf("open ground %+.3f with clouds; shadow takes %.3f of the clear light\n",
              open_change / open_clear, lost);
}

TEST(Clouds, SeenInTheSkyFromBelowAndSameBitsForAnyThreadCount) {
  ShadowScene s;
  s.in.clouds = s.clouds;
  const TerrainScene scene(s.in);
  Camera up;
  up.from = scene.origin() + Eigen::Vector3d(0, 0, 50);
  up.to = scene.origin() + Eigen::Vector3d(0, 0.001, 1000);
  up.vertical_fov_deg = 60.0;
  RenderSettings rs;
  rs.width = 40;
  rs.height = 30;
  rs.samples_per_pixel = 4;
  auto render_with = [&](int threads) {
    tbb::task_arena arena(threads);
    Image img;
    arena.execute([&] { img = render_image(scene, s.in, up, rs); });
    return img;
  };
  const Image one = render_with(1), two = render_with(2);
  EXPECT_EQ(one.pixels, two.pixels);
  // Looking up: cloud is whiter (less blue over red) than the clear sky.
  SceneInput no_clouds = s.in;
  no_clouds.clouds.enabled = false;
  tbb::task_arena arena(2);
  Image clear;
  arena.execute([&] { clear = render_image(scene, no_clouds, up, rs); });
  double clear_blue = 0, cloud_blue = 0;
  for (int y = 0; y < rs.height; ++y) {
    for (int x = 0; x < rs.width; ++x) {
      clear_blue += clear.at(x, y, 2) / clear.at(x, y, 0);
      cloud_blue += one.at(x, y, 2) / one.at(x, y, 0);
    }
  }
  EXPECT_LT(cloud_blue, 0.8 * clear_blue) << "clouds must show in the sky";
}

TEST(Clouds, NeedThePhysicalSky) {
  ShadowScene s;
  s.in.clouds = s.clouds;
  s.in.sky.model = SkyModel::Simple;
  const TerrainScene scene(s.in);
  RenderSettings rs;
  rs.width = rs.height = 4;
  rs.samples_per_pixel = 1;
  EXPECT_THROW(render_image(scene, s.in, looking_down(scene), rs), drift::Error);
}

}  // namespace
}  // namespace drift::render
