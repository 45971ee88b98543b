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

#include "render/camera_setup.h"
#include "render/renderer.h"
#include "render/terrain_scene.h"
#include "terrain/error.h"
#include "tests/dem_fixture.h"
#include "tests/render/render_fixtures.h"

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

TEST(Clouds, NoStreaksNearTheHorizon) {
  // Pixels looking 0.5-4 degrees up from a summit (3000 m) at the layer
  // (4500 m), tens of km away where rays meet it at grazing angles: each
  // filtered transmittance against the mean of 64 full-detail rays spread
  // over the pixel. A footprint taken across the ray alone (not stretched by
  // 1 / mu along it) aliases into streaks: its rms error is then 0.97 of a
  // point sample's (0.82 stretched by 1 / sqrt(mu)); the long axis gives
  // 0.67 and must stay under 0.8.
  const CloudLayer layer(options(0.4), {2e4, 5e3, 3000.0});
  const CloudLight light;       // no light: the transmittance is what is compared
  const float pixel = 0.0012f;  // radians: 1000 rows over ~70 degrees
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<float> elevation(0.5f, 4.0f), azimuth(0.0f, 6.28f), d(-0.5f, 0.5f);
  const auto ray = [](float el_deg, float az) {
    const float el = el_deg * std::numbers::pi_v<float> / 180.0f;
    return Eigen::Vector3f(std::cos(el) * std::sin(az), std::cos(el) * std::cos(az), std::sin(el));
  };
  const auto look = [&](const Eigen::Vector3f& dir, float spread) {
    CloudCrossing c;
    if (!layer.cross(Eigen::Vector3f::Zero(), dir, 1e30f, c)) return 1.0f;
    return cloud_look(layer, c, dir, light, spread * c.distance).transmittance;
  };
  double err2 = 0, spread2 = 0;
  const int pixels = 300, inside = 64;
  for (int i = 0; i < pixels; ++i) {
    const float el = elevation(rng), az = azimuth(rng);
    double box = 0;
    for (int k = 0; k < inside; ++k)
      box += look(ray(el + d(rng) * pixel * 57.2958f, az + d(rng) * pixel), 0.0f);
    box /= inside;
    const double filtered = look(ray(el, az), pixel), point = look(ray(el, az), 0.0f);
    err2 += (filtered - box) * (filtered - box);
    spread2 += (point - box) * (point - box);
  }
  std::printf("grazing rms error against the pixel's mean: filtered %.4f, point %.4f\n",
              std::sqrt(err2 / pixels), std::sqrt(spread2 / pixels));
  EXPECT_LT(std::sqrt(err2 / pixels), 0.8 * std::sqrt(spread2 / pixels));
}

TEST(Clouds, TopsFacingTheSunAreBrighterThanTheirLeeSides) {
  // The 2.5-D cloud seen from straight above under a sun 25 degrees up in
  // the east: over cloud of middling optical depth, the flanks whose tops
  // fall towards the sun (tau rising away from it) must read brighter than
  // the lee flanks. A flat layer (thickness ~0: no slope, no neighbour to
  // shade it) shows no such difference.
  const auto flank_ratio = [](double thickness) {
    CloudOptions o = options(0.5, 21);
    o.thickness = thickness;
    const CloudLayer layer(o, {0, 0, 0});
    CloudLight light;
    light.sun = Eigen::Vector3f::Ones();
    const float el = 25.0f * std::numbers::pi_v<float> / 180.0f;
    light.sun_dir = Eigen::Vector3f(std::cos(el), 0.0f, std::sin(el));
    const Eigen::Vector3f down(0, 0, -1);
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(0.0, 5e4);
    double sunward = 0, lee = 0;
    int n_sunward = 0, n_lee = 0;
    for (int i = 0; i < 20000; ++i) {
      CloudCrossing c;
      c.point = Eigen::Vector3f(static_cast<float>(u(rng)), static_cast<float>(u(rng)), 4500.0f);
      Eigen::Vector2f grad;
      const float tau = layer.optical_depth(c.point.x(), c.point.y(), 0.0, &grad);
      if (tau < 0.2f * o.density || tau > 0.8f * o.density) continue;
      const float lum = cloud_look(layer, c, down, light, 0.0f).radiance.x();
      // The sun is towards +x: tau falling towards it is a sunward flank.
      if (grad.x() < 0.0f)
        sunward += lum, ++n_sunward;
      else
        lee += lum, ++n_lee;
    }
    return (sunward / n_sunward) / (lee / n_lee);
  };
  const double thick = flank_ratio(500.0), flat = flank_ratio(1e-3);
  std::printf("sunward / lee flank brightness: 2.5-D %.3f, flat %.3f\n", thick, flat);
  EXPECT_GT(thick, 1.3);
  EXPECT_LT(std::abs(flat - 1.0), 0.05);
}

TEST(Clouds, AirBeneathKeepsTheLayersMeanSunlight) {
  // The mean transmittance towards the sun: 1 without cloud, about
  // 1 - coverage for an opaque layer, between for a thin one, and lower for
  // a lower sun (longer slant paths).
  const Eigen::Vector3f high = Eigen::Vector3f(0.3f, 0.0f, 0.95f).normalized();
  const Eigen::Vector3f low = Eigen::Vector3f(0.9f, 0.0f, 0.3f).normalized();
  EXPECT_NEAR(CloudLayer(options(0.0), {0, 0, 0}).mean_sun_transmittance(high), 1.0f, 1e-6f);
  CloudOptions opaque = options(0.4);
  opaque.density = 1e4;
  EXPECT_NEAR(CloudLayer(opaque, {0, 0, 0}).mean_sun_transmittance(high), 0.6f, 0.04f);
  const CloudLayer thin(options(0.4), {0, 0, 0});
  const float t_high = thin.mean_sun_transmittance(high), t_low = thin.mean_sun_transmittance(low);
  std::printf("mean transmittance towards the sun: high %.3f, low %.3f\n", t_high, t_low);
  EXPECT_GT(t_high, 0.6f);
  EXPECT_LT(t_high, 0.95f);
  EXPECT_LT(t_low, t_high);
  // No sun, no shadow to cast.
  EXPECT_EQ(thin.mean_sun_transmittance({1.0f, 0.0f, -0.1f}), 1.0f);
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
  const Camera up = drift::testing::camera_from_to(scene, {0, 0, 50}, {0, 0.001, 1000}, 60.0);
  const RenderSettings rs = drift::testing::frame_settings(40, 30, 4);
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
