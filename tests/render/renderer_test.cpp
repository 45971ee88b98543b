// Path tracer basics against closed forms: the cosine law under a sun, the white
// furnace, grid-geometry hits on an analytic plane, and determinism across
// thread counts.
#include "render/renderer.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "render/camera_setup.h"
#include "render/terrain_scene.h"
#include "terrain/bilinear.h"
#include "terrain/derivatives.h"
#include "terrain/error.h"
#include "tests/dem_fixture.h"
#include "tests/render/render_fixtures.h"
#include "tests/render/snow_layer.h"

using namespace drift::render;
using drift::terrain::HeightField;

namespace {

// A square DEM of n x n cells of `cell` metres, z = f(x, y) at the cell centres
// in the local georeference's coordinates (NW corner at the origin).
template <class F>
HeightField make_dem(int n, double cell, F f) {
  return drift::testing::dem_from(n, cell, 0.5, f);
}

// Flat ground of albedo 0.5 at `height` m (64 cells of 10 m) under a black
// constant sky: only the sun lights it.
SceneInput flat_ground_black_sky(double height) {
  SceneInput in;
  in.terrain = make_dem(64, 10.0, [height](double, double) { return height; });
  in.surface.ground.albedo = {0.5f, 0.5f, 0.5f};
  in.sky.constant = true;
  in.sky.intensity = 0.0f;
  return in;
}

Camera looking_down(const TerrainScene& scene, double height) {
  Camera c;
  c.from = scene.origin() + Eigen::Vector3d(0, 0, height);
  c.to = scene.origin() + Eigen::Vector3d(0, 0.001, 0);  // straight down, north up
  c.vertical_fov_deg = 10.0;
  return c;
}

double mean_channel(const Image& img, int c) {
  double s = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) s += img.at(x, y, c);
  return s / (img.width * img.height);
}

}  // namespace

TEST(TerrainScene, SmoothNormalsAreHornsVertexNormalsBlended) {
  // Rough ground of 12 x 12 cells: the shading normal anywhere (the DEM's
  // edge rows and points beyond it included) is the bilinear blend of
  // Horn's normals at the four vertices around it, normalised, whichever
  // path computes it (inside, one shared 4x4 stencil of heights).
  SceneInput in;
  in.terrain = make_dem(12, 10.0, [](double x, double y) {
    return 20.0 * std::sin(0.031 * x + 0.4) * std::cos(0.047 * y) + 0.002 * x * y;
  });
  const HeightField& dem = in.terrain;
  const TerrainScene scene(in);
  const auto vertex = [&](int c, int r) {
    const drift::terrain::Gradient g = drift::terrain::horn_gradient(dem, c, r);
    return Eigen::Vector3f(-g.dzdx, -g.dzdy, 1.0f).normalized();
  };
  int checked = 0;
  for (double col = -0.7; col < 12.0; col += 0.37) {
    for (double row = -0.6; row < 12.0; row += 0.41) {
      const auto world = dem.geo().cell_center(col, row);
      const Eigen::Vector3f local =
          scene.to_local(Eigen::Vector3d(world[0], world[1], scene.origin().z()));
      const auto c = drift::terrain::clamped_cell(col, row, 12, 12);
      const Eigen::Vector3f expected =
          drift::terrain::bilinear_blend(vertex(c.x0, c.y0), vertex(c.x1, c.y0), vertex(c.x0, c.y1),
                                         vertex(c.x1, c.y1), static_cast<float>(c.tx),
                                         static_cast<float>(c.ty))
              .normalized();
      const Eigen::Vector3f n = scene.smooth_normal(local.x(), local.y());
      ASSERT_NEAR((n - expected).norm(), 0.0f, 2e-5f) << "at column " << col << ", row " << row;
      ++checked;
    }
  }
  EXPECT_GT(checked, 900);
}

TEST(Renderer, CosineLawUnderTheSun) {
  // Flat Lambertian ground, black sky, one bounce: L = albedo/pi * E * sin(elevation).
  SceneInput in = flat_ground_black_sky(100.0);
  in.sun.color = {1, 1, 1};
  in.sun.irradiance = 2.0;
  const TerrainScene scene(in);
  RenderSettings rs = drift::testing::frame_settings(16, 16, 8);
  rs.max_depth = 2;
  for (double elevation : {10.0, 30.0, 60.0, 90.0}) {
    in.sun.elevation_deg = elevation;
    const Image img = render_image(scene, in, looking_down(scene, 500.0), rs);
    const double expected =
        0.5 / std::numbers::pi * 2.0 * std::sin(elevation * std::numbers::pi / 180.0);
    // The sun's 0.53-degree disc changes cos by < 0.5 % even at 10 degrees.
    EXPECT_NEAR(mean_channel(img, 0), expected, 0.01 * expected) << "elevation " << elevation;
  }
}

TEST(Renderer, WhiteFurnace) {
  // Albedo 1 inside a sky of constant radiance 1: every path returns 1, whatever
  // the geometry, so bumpy terrain must look exactly as bright as the sky.
  SceneInput in;
  in.terrain = make_dem(
      96, 5.0, [](double x, double y) { return 40.0 * std::sin(x / 30.0) * std::cos(y / 25.0); });
  in.surface.ground.albedo = {1, 1, 1};
  in.sky.constant = true;
  in.sky.intensity = 1.0f;
  in.sun.irradiance = 0.0;
  const TerrainScene scene(in);
  RenderSettings rs = drift::testing::frame_settings(24, 24, 32);
  rs.max_depth = 256;
  const Image img = render_image(scene, in, looking_down(scene, 600.0), rs);
  // Russian roulette keeps the mean at 1; 18432 paths give a standard error ~1e-3.
  EXPECT_NEAR(mean_channel(img, 1), 1.0, 0.01);
}

TEST(Renderer, WetCoatedFurnace) {
  // A flat plane under a constant sky of radiance 1, one bounce: each pixel
  // is the directional albedo of the material. Dry, it is the albedo (exactly
  // so with bounces alone, within the noise with the sky sampled too); wet
  // and white, 1 (what the coat does not reflect the ground returns); over
  // bumpy terrain with every bounce, still at most 1.
  SceneInput in;
  in.terrain = make_dem(96, 50.0, [](double, double) { return 0.0; });
  in.sky.constant = true;
  in.sky.intensity = 1.0f;
  in.sun.irradiance = 0.0;
  RenderSettings rs;
  rs.width = rs.height = 24;
  rs.samples_per_pixel = 128;
  rs.max_depth = 1;
  auto furnace = [&](const Material& m, bool sample_sky) {
    in.surface.ground = m;
    rs.sample_sky = sample_sky;
    const TerrainScene scene(in);
    Camera c;  // looking down at 45 degrees
    c.from = scene.origin() + Eigen::Vector3d(0, -300, 300);
    c.to = scene.origin();
    c.vertical_fov_deg = 10.0;
    return mean_channel(render_image(scene, in, c, rs), 1);
  };
  const Material dry{{0.5f, 0.5f, 0.5f}, 0.0f, 0.0f}, wet{{1, 1, 1}, 0.0f, 1.0f};
  const double dry_bsdf = furnace(dry, false), dry_mis = furnace(dry, true);
  const double wet_bsdf = furnace(wet, false), wet_mis = furnace(wet, true);
  const double half_wet = furnace({{1, 1, 1}, 0.0f, 0.5f}, true);
  std::printf(
      "furnace, flat, one bounce: dry 0.5 -> %.5f (bounces), %.5f (MIS); wet white -> %.5f "
      "(bounces), %.5f (MIS); half wet white %.5f\n",
      dry_bsdf, dry_mis, wet_bsdf, wet_mis, half_wet);
  EXPECT_NEAR(dry_bsdf, 0.5, 1e-5) << "dry, cosine-sampled: the analytic albedo";
  EXPECT_NEAR(dry_mis, 0.5, 2.5e-3);  // 73728 paths: standard error ~5e-4
  for (double white : {wet_bsdf, wet_mis, half_wet}) EXPECT_NEAR(white, 1.0, 3e-3);

  // Bumpy, wet and white, every bounce: the furnace still returns at most 1.
  in.terrain = make_dem(
      96, 5.0, [](double x, double y) { return 40.0 * std::sin(x / 30.0) * std::cos(y / 25.0); });
  in.surface.ground = wet;
  rs.sample_sky = true;
  rs.samples_per_pixel = 32;
  const TerrainScene scene(in);
  rs.max_depth = 256;
  const double bumpy = mean_channel(render_image(scene, in, looking_down(scene, 600.0), rs), 1);
  std::printf("furnace, bumpy, wet white, all bounces -> %.5f\n", bumpy);
  EXPECT_LE(bumpy, 1.0 + 0.01);
  EXPECT_GT(bumpy, 0.95);
}

TEST(Renderer, GridHitsLieOnAnAnalyticPlane) {
  // z = 0.3 x - 0.2 y + 50 is represented exactly by bilinear grid cells.
  SceneInput in;
  in.terrain = make_dem(50, 2.0, [](double x, double y) { return 0.3 * x - 0.2 * y + 50.0; });
  const TerrainScene scene(in);
  const Eigen::Vector3f n_expected = Eigen::Vector3f(-0.3f, 0.2f, 1.0f).normalized();
  for (int i = 0; i < 20; ++i) {
    const float x = -40.0f + 4.0f * i, y = 30.0f - 3.0f * i;
    Hit hit;
    ASSERT_TRUE(scene.intersect({x, y, 500.0f}, {0, 0, -1}, hit));
    const Eigen::Vector3d world = scene.origin() + hit.position.cast<double>();
    const double x_from_nw = world.x(), y_from_nw = world.y();  // local georef: NW at (0, 0)
    EXPECT_NEAR(world.z(), 0.3 * x_from_nw - 0.2 * y_from_nw + 50.0, 1e-3);
    EXPECT_GT(hit.normal.dot(n_expected), 0.9999f);
  }
}

TEST(Renderer, ShadingNormalsAreTheTerrainsHornNormals) {
  // The scene computes normals from its vertex buffer at each hit; at a vertex
  // they must be terrain::normals of the same DEM (vertical exaggeration
  // included), interior and border alike.
  SceneInput in;
  in.vertical_exaggeration = 1.5;
  in.terrain = make_dem(24, 5.0, [](double x, double y) {
    return 80.0 + 0.002 * (x - 40) * (x - 40) - 0.003 * (y + 70) * (y + 70) + 0.1 * x;
  });
  const TerrainScene scene(in);
  const auto expected = drift::terrain::normals(in.terrain, 1.5f);
  const auto nw = in.terrain.geo().cell_center(0, 0);
  for (const auto& [x, row] : {std::pair{0, 0}, {5, 7}, {23, 12}, {11, 23}, {17, 3}}) {
    const Eigen::Vector3d at = Eigen::Vector3d(nw[0] + 5.0 * x, nw[1] - 5.0 * row, 1e4);
    Hit hit;
    ASSERT_TRUE(scene.intersect(scene.to_local(at), {0, 0, -1}, hit));
    const Eigen::Vector3f n = expected(x, row);
    EXPECT_GT(hit.normal.dot(n), 1.0f - 1e-6f)
        << "vertex (" << x << ", " << row << "): " << hit.normal.transpose() << " vs "
        << n.transpose();
  }
}

TEST(Renderer, SameBitsForAnyThreadCount) {
  SceneInput in;
  in.terrain = make_dem(64, 10.0, [](double x, double y) {
    return 200.0 * std::exp(-((x - 320) * (x - 320) + (y + 320) * (y + 320)) / 40000.0);
  });
  const TerrainScene scene(in);
  RenderSettings rs;
  rs.width = 70;  // not a multiple of the tile size
  rs.height = 45;
  rs.samples_per_pixel = 4;
  const Camera cam = default_camera(scene);
  auto render_with = [&](int threads) {
    tbb::task_arena arena(threads);
    Image img;
    arena.execute([&] { img = render_image(scene, in, cam, rs); });
    return img;
  };
  const Image one = render_with(1), two = render_with(2), four = render_with(4);
  EXPECT_EQ(one.pixels, two.pixels);
  EXPECT_EQ(one.pixels, four.pixels);
  rs.seed = 2;
  EXPECT_NE(render_with(2).pixels, one.pixels) << "the seed must change the noise";
}

TEST(Renderer, AllNodataTerrainIsAnError) {
  SceneInput in;
  in.terrain = make_dem(8, 1.0, [](double, double) { return std::nan(""); });
  EXPECT_THROW(TerrainScene scene(in), drift::Error);
}

TEST(Renderer, MeshRoofShadowsTheGround) {
  // A 40 m square roof 20 m above flat ground, sun overhead, black sky: the
  // ground under the roof's centre is dark, open ground follows the cosine law.
  SceneInput in = flat_ground_black_sky(0.0);
  in.sun.elevation_deg = 90.0;
  in.sun.color = {1, 1, 1};
  in.sun.irradiance = 1.0;
  const TerrainScene probe(in);
  drift::terrain::PlacedMesh roof;
  roof.position = probe.origin();  // the DEM's centre, ground level
  const float z = 20.0f;
  for (auto [x, y] : {std::pair{-20.f, -20.f}, {20.f, -20.f}, {20.f, 20.f}, {-20.f, 20.f}}) {
    roof.mesh.positions.emplace_back(x, y, z);
  }
  roof.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  in.meshes.push_back(roof);
  const TerrainScene scene(in);
  Hit hit;
  ASSERT_TRUE(scene.intersect({0, 0, 100}, {0, 0, -1}, hit));
  EXPECT_NEAR(hit.position.z(), z, 1e-3f) << "the first hit from above is the roof";
  EXPECT_TRUE(scene.occluded({0, 0, 0.01f}, {0, 0, 1}, 1e30f)) << "under the roof";
  EXPECT_FALSE(scene.occluded({60, 0, 0.01f}, {0, 0, 1}, 1e30f)) << "open ground";
}

TEST(Camera, FocalLengthGivesTheFieldOfViewOverTheSensor) {
  SceneInput in;
  in.terrain = make_dem(8, 10.0, [](double, double) { return 0.0; });
  const TerrainScene scene(in);
  Camera c = drift::testing::camera_from_to(scene, {0, 0, 10}, {0, 100, 10});
  c.focal_length_mm = 50.0;  // on 36 mm: 39.6 degrees across
  const CameraRays rays = make_camera_rays(scene, c, 160, 90);
  const Eigen::Vector3f edge = rays.direction(160.0f, 45.0f);
  EXPECT_NEAR(std::atan2(edge.x(), edge.y()), std::atan(18.0 / 50.0), 1e-5);
}

TEST(Camera, ThinLensRaysMeetOnTheFocalPlane) {
  SceneInput in;
  in.terrain = make_dem(8, 10.0, [](double, double) { return 0.0; });
  const TerrainScene scene(in);
  Camera c = drift::testing::camera_from_to(scene, {0, 0, 10}, {0, 100, 10});
  c.focal_length_mm = 100.0;
  c.f_number = 2.0;  // 50 mm aperture: 25 mm lens radius
  c.focus_distance = 40.0;
  const CameraRays rays = make_camera_rays(scene, c, 64, 48);
  EXPECT_FLOAT_EQ(rays.lens_radius, 0.025f);
  Eigen::Vector3f o0, d0;
  rays.ray(10.3f, 30.7f, 0.0f, 0.0f, o0, d0);  // lens centre: the pinhole ray
  const Eigen::Vector3f focus = o0 + d0 * (40.0f / d0.dot(rays.forward));
  float spread = 0.0f;
  for (float u : {0.1f, 0.5f, 0.9f}) {
    for (float v : {0.2f, 0.7f}) {
      Eigen::Vector3f o, d;
      rays.ray(10.3f, 30.7f, u, v, o, d);
      spread = std::max(spread, (o - rays.eye).norm());
      const float t = (focus - o).dot(rays.forward) / d.dot(rays.forward);
      EXPECT_NEAR((o + d * t - focus).norm(), 0.0f, 1e-4f);  // sharp at 40 m
    }
  }
  EXPECT_GT(spread, 0.01f);  // rays do leave from across the lens
}

TEST(Renderer, SkyMaskAndSnowCoverageAovs) {
  SceneInput in;
  in.terrain = make_dem(64, 10.0, [](double, double) { return 0.0; });
  in.surface.layers.push_back(
      drift::testing::snow_layer(make_dem(64, 10.0, [](double, double) { return 0.25; })));
  in.sky.model = SkyModel::Simple;
  const TerrainScene scene(in);
  // Level, looking north across the plane: sky above, ground below.
  const Camera c = drift::testing::camera_from_to(scene, {0, -300, 20}, {0, 300, 20});
  const Image img = render_image(scene, in, c, drift::testing::frame_settings(16, 16, 2));
  const int sky = img.channel_index("mask.sky"), snow = img.channel_index("coverage.snow");
  ASSERT_GE(sky, 0);
  ASSERT_GE(snow, 0);
  EXPECT_FLOAT_EQ(img.at(8, 0, sky), 1.0f);
  EXPECT_FLOAT_EQ(img.at(8, 15, sky), 0.0f);
  EXPECT_FLOAT_EQ(img.at(8, 15, snow), 0.25f);
  EXPECT_FLOAT_EQ(img.at(8, 0, snow), 0.0f);
  // The ground's own channel takes the rest: the shares of a ground pixel sum to 1.
  const int ground = img.channel_index("coverage.ground");
  ASSERT_GE(ground, 0);
  EXPECT_FLOAT_EQ(img.at(8, 15, ground), 0.75f);
  EXPECT_FLOAT_EQ(img.at(8, 0, ground), 0.0f);
}

namespace {

// Adaptive sampling on a uniform scene: flat ground seen straight down under
// the physical sky, so every pixel has the same mean and the spread across
// pixels measures each pixel's noise.
struct AdaptiveRun {
  Image image;
  double mean_samples = 0, relative_spread = 0;
};

AdaptiveRun render_adaptive(float noise_target, int threads = 2) {
  SceneInput in;
  in.terrain = make_dem(64, 10.0, [](double, double) { return 100.0; });
  in.surface.ground.albedo = {0.4f, 0.4f, 0.4f};
  in.sun.elevation_deg = 40.0;
  in.sun.angular_diameter_deg = 5.0;  // soft: some sun samples miss the cone's visible part
  const TerrainScene scene(in);
  RenderSettings rs;
  rs.width = rs.height = 24;
  rs.samples_per_pixel = 512;
  rs.noise_target = noise_target;
  AdaptiveRun run;
  tbb::task_arena arena(threads);
  arena.execute([&] { run.image = render_image(scene, in, looking_down(scene, 50.0), rs); });
  const int samples = run.image.channel_index("samples");
  double sum = 0, sum2 = 0, n = 0;
  for (int y = 0; y < run.image.height; ++y)
    for (int x = 0; x < run.image.width; ++x) {
      const double l = run.image.at(x, y, 1);  // green: most of the luminance
      sum += l;
      sum2 += l * l;
      run.mean_samples += samples >= 0 ? run.image.at(x, y, samples) : rs.samples_per_pixel;
      ++n;
    }
  const double mean = sum / n;
  run.relative_spread = std::sqrt(std::max(0.0, sum2 / n - mean * mean)) / mean;
  run.mean_samples /= n;
  return run;
}

}  // namespace

TEST(AdaptiveSampling, StopsAtTheNoiseTarget) {
  // Each pixel stops when its own estimate of the relative standard error is
  // below the target: the pixels' spread around their common mean is then
  // about the target (early stopping biases it a little upwards), and a
  // tighter target takes more samples.
  const AdaptiveRun loose = render_adaptive(0.01f), tight = render_adaptive(0.004f);
  EXPECT_LT(loose.relative_spread, 1.5 * 0.01);
  EXPECT_LT(tight.relative_spread, 1.5 * 0.004);
  EXPECT_GT(loose.mean_samples, 16.0) << "the target, not the minimum, must stop the pixels";
  EXPECT_LT(loose.mean_samples, 512.0);
  EXPECT_GT(tight.mean_samples, 2.0 * loose.mean_samples);
  // Whatever the target, every pixel takes at least min_samples, in whole
  // batches of 8 until the cap.
  const int samples = loose.image.channel_index("samples");
  ASSERT_GE(samples, 0);
  for (float s : {loose.image.at(0, 0, samples), loose.image.at(5, 7, samples)}) {
    EXPECT_GE(s, 16.0f);
    EXPECT_EQ(static_cast<int>(s) % 8, 0);
  }
}

TEST(AdaptiveSampling, SameBitsForAnyThreadCountAndOffByDefault) {
  EXPECT_EQ(render_adaptive(0.02f, 1).image.pixels, render_adaptive(0.02f, 2).image.pixels);
  const AdaptiveRun off = render_adaptive(0.0f);
  EXPECT_LT(off.image.channel_index("samples"), 0)
      << "no samples channel without adaptive sampling";
}
