// The ground beyond the DEM's edge (render/surround.h): a watertight,
// continuous seam, the fallback's continuation, surround rasters (finest
// wins, blended in), and rays that hit it (AOVs report ground).
#include "render/surround.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>

#include "render/renderer.h"
#include "render/terrain_scene.h"

namespace drift::render {
namespace {

// A local DEM's vertices as TerrainScene lays them out (row 0 north), and its
// heights as the scene holds them.
struct TestDem {
  std::vector<Eigen::Vector3f> vertices;
  HeightGrid heights;
  DemVertices view;
  TestDem(int w, int h, float cell) {
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        const float x = c * cell, y = -r * cell;
        vertices.emplace_back(x, y, 300.0f + 40.0f * std::sin(x / 70.0f) + 0.3f * y);
      }
    heights = {w, h, 0.0f, 0.0f, cell, cell, {}};
    for (const Eigen::Vector3f& v : vertices) heights.z.push_back(v.z());
    view = {&heights, w, h, cell, cell, Eigen::Vector3d(500000.0, 4000000.0, 1000.0), 1.0f};
  }
};

TEST(Surround, SeamIsWatertightAndContinuous) {
  const TestDem dem(41, 29, 10.0f);
  SurroundOptions options;
  options.reach = 20000.0;
  const SurroundGrids ring = build_surround(dem.view, options);
  ASSERT_FALSE(ring.grids.empty());
  // The north strip's first row is the DEM's north row, bit for bit.
  for (int c = 0; c < 41; ++c) EXPECT_EQ(ring.vertices[c], dem.vertices[c]) << c;
  // Across the seam the height changes no faster than the ground's slope
  // (at most 0.6 here) plus the relaxation: within 1 m of the edge, under 1 m.
  const SurroundHeight height(dem.view, options);
  double worst = 0.0;
  for (int r = 0; r < 29; ++r) {
    for (const float eps : {0.01f, 0.1f, 1.0f}) {
      const float y = -r * 10.0f;
      const float west = height(-eps, y, 10.0f), east = height(400.0f + eps, y, 10.0f);
      worst = std::max({worst, double(std::abs(west - dem.vertices[r * 41].z())) / eps,
                        double(std::abs(east - dem.vertices[r * 41 + 40].z())) / eps});
    }
  }
  EXPECT_LT(worst, 1.0) << "steepest rise per metre across the seam";
}

TEST(Surround, FallbackContinuesTheRangeAndSinksWithTheEarth) {
  const TestDem dem(41, 29, 10.0f);
  SurroundOptions options;
  const SurroundHeight height(dem.view, options);
  double s = 0, s2 = 0;
  const int n = 400;
  const float d = 40000.0f;  // far out east
  for (int i = 0; i < n; ++i) {
    const float z = height(400.0f + d, -140.0f + 100.0f * (i - n / 2), 500.0f);
    s += z, s2 += double(z) * z;
  }
  const double mean = s / n, sd = std::sqrt(s2 / n - mean * mean);
  // The DEM's mean height (259 m), less the Earth's drop at 40 km (126 m),
  // with ridges of the DEM's relief (its deviation is 37 m) around it: never
  // a flat plane.
  double dem_mean = 0;
  for (const auto& v : dem.vertices) dem_mean += v.z() / dem.vertices.size();
  EXPECT_NEAR(dem_mean, 259.0, 1.0);
  EXPECT_NEAR(mean, dem_mean - 125.6, 60.0);
  EXPECT_GT(sd, 10.0);
}

TEST(Surround, FinestRasterWinsAndBlendsIn) {
  const TestDem dem(41, 29, 10.0f);
  // A coarse raster around everything (100 m, 500 m high) and a finer one
  // (50 m, 800 m) east of the DEM; CRS coordinates (origin + local).
  terrain::GeoReference coarse_geo;
  coarse_geo.geotransform = {490000.0, 100.0, 0.0, 4010000.0, 0.0, -100.0};
  terrain::HeightField coarse(200, 200, 500.0f, coarse_geo);
  terrain::GeoReference fine_geo;
  fine_geo.geotransform = {500600.0, 50.0, 0.0, 4000500.0, 0.0, -50.0};
  terrain::HeightField fine(40, 40, 800.0f, fine_geo);
  SurroundOptions options;
  options.rasters = {coarse, fine};
  options.blend = 300.0;
  const SurroundHeight height(dem.view, options);
  auto drop = [](double d) { return d * d / (2.0 * 6371000.0); };
  // East, inside the fine raster and past the blend: the fine one's height.
  EXPECT_NEAR(height(1400.0f, -200.0f, 50.0f), 800.0f - 1000.0f - drop(1000.0), 1e-2);
  // North, only the coarse raster.
  EXPECT_NEAR(height(200.0f, 1000.0f, 50.0f), 500.0f - 1000.0f - drop(1000.0), 1e-2);
  // At the seam the DEM, and halfway through the blend a mix of the two.
  const float edge = dem.vertices[41 * 20].z();
  EXPECT_NEAR(height(-0.001f, -200.0f, 10.0f), edge, 0.01f);
  const float mid = height(-150.0f, -200.0f, 10.0f);
  EXPECT_GT(mid, std::min(edge, -500.0f) - 1.0f);
  EXPECT_LT(mid, std::max(edge, -500.0f) + 1.0f);
}

TEST(Surround, ARasterTheDemWasCutFromGoesOnAsItself) {
  // The DEM is a crop of a raster (the same surface, 10 m cells on the DEM's
  // vertices) given as its surround: out to the blend's width and past it, the
  // surround is that surface, not a band flattened towards the edge.
  const TestDem dem(41, 29, 10.0f);
  const auto surface = [](double x, double y) {  // local metres, as TestDem
    return 300.0 + 40.0 * std::sin(x / 70.0) + 0.3 * y;
  };
  terrain::GeoReference geo;
  const int margin = 40;  // cells of raster around the DEM
  geo.geotransform = {500000.0 - 5.0 - 10.0 * margin,  10.0, 0.0,
                      4000000.0 + 5.0 + 10.0 * margin, 0.0,  -10.0};
  terrain::HeightField raster(41 + 2 * margin, 29 + 2 * margin, 0.0f, geo);
  for (int r = 0; r < raster.height(); ++r)
    for (int c = 0; c < raster.width(); ++c)
      raster(c, r) =
          static_cast<float>(1000.0 + surface(10.0 * (c - margin), -10.0 * (r - margin)));
  SurroundOptions options;
  options.rasters = {raster};  // blend: 10 cells, 100 m
  const SurroundHeight height(dem.view, options);
  double worst = 0.0;
  for (const float d : {5.0f, 20.0f, 50.0f, 90.0f, 150.0f}) {
    for (float t = 0.0f; t <= 1.0f; t += 0.125f) {
      const float along_x = 400.0f * t, along_y = -280.0f * t;
      const std::array<Eigen::Vector2f, 4> points = {
          Eigen::Vector2f(along_x, d), Eigen::Vector2f(along_x, -280.0f - d),
          Eigen::Vector2f(-d, along_y), Eigen::Vector2f(400.0f + d, along_y)};
      for (const Eigen::Vector2f& p : points) {
        const double drop = double(d) * d / (2.0 * 6371000.0);
        worst =
            std::max(worst, std::abs(height(p.x(), p.y(), 10.0f) + drop - surface(p.x(), p.y())));
      }
    }
  }
  // Bilinear between 10 m samples of the sine: within 0.1 m of it.
  EXPECT_LT(worst, 0.15);
}

TEST(Surround, RaysHitItAndAovsReportGround) {
  // A flat 640 m DEM seen from its centre, looking out level and a little
  // down: past the edge the rays hit the surround (depth beyond the DEM, no
  // sky) below the horizon; without a surround they escape to the sky.
  SceneInput in;
  in.terrain = terrain::HeightField(64, 64, 100.0f, terrain::local_georeference(10.0));
  in.sky.constant = true;
  in.sky.intensity = 1.0f;
  in.sun.irradiance = 0.0;
  Camera camera;
  RenderSettings rs;
  rs.width = 16, rs.height = 16, rs.samples_per_pixel = 1, rs.max_depth = 1;
  auto lower_row = [&](double reach, float& sky, float& depth) {
    in.surround.reach = reach;
    const TerrainScene scene(in);
    camera.from = scene.origin() + Eigen::Vector3d(0, 0, 30.0);
    camera.to = scene.origin() + Eigen::Vector3d(1000.0, 0, 0.0);
    camera.vertical_fov_deg = 2.0;
    const Image img = render_image(scene, in, camera, rs);
    const int s = img.channel_index("mask.sky"), d = img.channel_index("Z");
    sky = depth = 0.0f;
    for (int x = 0; x < 16; ++x) sky += img.at(x, 15, s) / 16, depth += img.at(x, 15, d) / 16;
  };
  float sky, depth;
  lower_row(0.0, sky, depth);
  EXPECT_EQ(sky, 1.0f);  // a cut: the rays leave the world
  lower_row(100000.0, sky, depth);
  EXPECT_EQ(sky, 0.0f);
  EXPECT_GT(depth, 320.0f);  // beyond the DEM's edge, 320 m away
}

TEST(Surround, FarSlopesAreShadedSmoothNotAsFacets) {
  // A flat 640 m DEM inside a surround raster of smooth hills (100 m cells).
  // Beyond the DEM the ring's cells grow to hundreds of metres; its shading
  // normals (vertex normals, interpolated) must follow the hills' slope far
  // better than its flat facets do.
  SceneInput in;
  in.terrain = terrain::HeightField(64, 64, 0.0f, terrain::local_georeference(10.0));
  terrain::GeoReference geo;
  geo.geotransform = {-30000.0, 100.0, 0.0, 30000.0, 0.0, -100.0};
  terrain::HeightField hills(600, 600, 0.0f, geo);
  auto z = [](double x, double y) { return 300.0 * std::sin(x / 900.0) * std::cos(y / 700.0); };
  for (int r = 0; r < 600; ++r)
    for (int c = 0; c < 600; ++c)
      hills(c, r) =
          static_cast<float>(z(-30000.0 + (c + 0.5) * 100.0, 30000.0 - (r + 0.5) * 100.0));
  in.surround.rasters = {hills};
  const TerrainScene scene(in);
  const Eigen::Vector3d o = scene.origin();
  double smooth_error = 0.0, facet_error = 0.0;
  int n = 0;
  for (double d = 3000.0; d < 15000.0; d += 97.0) {
    for (const double side : {-1.0, 1.0}) {
      const Eigen::Vector3d world(o.x() + side * d, o.y() + 0.37 * d, 0.0);
      const Eigen::Vector3f p = scene.to_local(world);
      Hit hit, hx, hy;
      const Eigen::Vector3f down(0, 0, -1);
      ASSERT_TRUE(scene.intersect({p.x(), p.y(), 5000.0f}, down, hit));
      // The facet under the point, from two more hits 0.5 m away.
      ASSERT_TRUE(scene.intersect({p.x() + 0.5f, p.y(), 5000.0f}, down, hx));
      ASSERT_TRUE(scene.intersect({p.x(), p.y() + 0.5f, 5000.0f}, down, hy));
      const Eigen::Vector3f facet =
          (hx.position - hit.position).cross(hy.position - hit.position).normalized();
      // The hills' own normal there (the Earth's curvature tilts it by < 2.4 mrad).
      const double x = world.x(), y = world.y(), h = 1.0;
      const Eigen::Vector3f truth = Eigen::Vector3d(-(z(x + h, y) - z(x - h, y)) / (2 * h),
                                                    -(z(x, y + h) - z(x, y - h)) / (2 * h), 1.0)
                                        .normalized()
                                        .cast<float>();
      smooth_error += std::acos(std::min(1.0f, hit.normal.dot(truth)));
      facet_error += std::acos(std::min(1.0f, facet.dot(truth)));
      ++n;
    }
  }
  smooth_error *= 180.0 / M_PI / n, facet_error *= 180.0 / M_PI / n;
  std::printf("mean angle to the hills' normal 3-15 km out: shading %.2f deg, facets %.2f deg\n",
              smooth_error, facet_error);
  // Measured 3.2 against 5.6 degrees (what is left is the ring's coarse
  // cells cutting the hills' crests, not the shading); with Embree's u and v
  // swapped the shading would be off by 17.5.
  EXPECT_LT(smooth_error, 0.7 * facet_error);
  EXPECT_LT(smooth_error, 4.0);
}

}  // namespace
}  // namespace drift::render
