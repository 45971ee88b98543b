// A pixel's samples traced together (camera rays and the first vertex's sun
// shadow rays as Embree packets: TerrainScene::intersect_coherent and
// occluded_coherent, PathTracer::trace_coherent) give what tracing them one
// by one gives, bit for bit, on both terrain geometries.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "render/camera_setup.h"
#include "render/path_tracer.h"
#include "render/terrain_scene.h"
#include "tests/dem_fixture.h"

using namespace drift::render;

namespace {

// A hill on a slope (64 x 64 cells of 10 m) under the physical sky and a low
// sun: shadows, sky light and bounces all count.
SceneInput hill_scene() {
  SceneInput in;
  in.terrain = drift::testing::dem_from(64, 10.0, 0.5, [](double x, double y) {
    return 0.2 * x + 200.0 * std::exp(-((x - 320) * (x - 320) + (y + 320) * (y + 320)) / 20000.0);
  });
  in.surface.ground.albedo = {0.3f, 0.3f, 0.3f};
  in.sun.elevation_deg = 20.0;
  in.sun.azimuth_deg = 250.0;
  return in;
}

void expect_same(const PixelSample& a, const PixelSample& b) {
  EXPECT_EQ(a.radiance, b.radiance);
  EXPECT_EQ(a.hit, b.hit);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.object, b.object);
  EXPECT_EQ(a.normal, b.normal);
  EXPECT_EQ(a.albedo, b.albedo);
  EXPECT_EQ(a.sky, b.sky);
}

class CoherentRays : public ::testing::TestWithParam<TerrainGeometry> {};

TEST_P(CoherentRays, PacketsHitWhatSingleRaysHit) {
  const SceneInput in = hill_scene();
  const TerrainScene scene(in, GetParam());
  const Camera camera = default_camera(scene);
  const CameraRays rays = make_camera_rays(scene, camera, 24, 16);
  int hits = 0, blocked_rays = 0;
  for (int py = 0; py < 16; py += 3) {
    for (int px = 0; px < 24; px += 5) {
      // Seven rays across the pixel (a packet with an unused lane).
      constexpr int n = 7;
      Eigen::Vector3f origins[n], dirs[n], sun[n];
      RayCone cones[n];
      Hit packet[n];
      bool found[n];
      for (int i = 0; i < n; ++i) {
        origins[i] = rays.eye;
        dirs[i] = rays.direction(px + (i + 0.5f) / n, py + 0.5f);
        cones[i] = {0.1f, 0.001f};
      }
      scene.intersect_coherent(n, origins, dirs, cones, packet, found);
      Eigen::Vector3f points[n];
      for (int i = 0; i < n; ++i) {
        Hit single;
        const bool met = scene.intersect(origins[i], dirs[i], single, cones[i]);
        ASSERT_EQ(met, found[i]);
        if (!met) {
          points[i] = origins[i];
          continue;
        }
        ++hits;
        EXPECT_EQ(single.distance, packet[i].distance);
        EXPECT_EQ(single.normal, packet[i].normal);
        EXPECT_EQ(single.material.albedo, packet[i].material.albedo);
        points[i] = single.position + 0.01f * single.normal;
        sun[i] = Eigen::Vector3f(std::cos(0.3f + 0.1f * i), 0.2f, 0.25f).normalized();
      }
      for (int i = 0; i < n; ++i)
        if (!found[i]) sun[i] = Eigen::Vector3f(0, 0, 1);
      bool blocked[n];
      scene.occluded_coherent(n, points, sun, 1e30f, blocked);
      for (int i = 0; i < n; ++i) {
        EXPECT_EQ(blocked[i], scene.occluded(points[i], sun[i], 1e30f));
        blocked_rays += blocked[i];
      }
    }
  }
  EXPECT_GT(hits, 100) << "most camera rays meet the hill";
  EXPECT_GT(blocked_rays, 5) << "some shadow rays meet the hill";
}

TEST_P(CoherentRays, PixelBatchesAreTracesSampleBySample) {
  const SceneInput in = hill_scene();
  const TerrainScene scene(in, GetParam());
  RenderSettings settings;
  settings.width = 24;
  settings.height = 16;
  const CameraRays camera = make_camera_rays(scene, default_camera(scene), 24, 16);
  const PathTracer tracer(scene, in, camera, settings);
  int lit = 0;
  for (int py = 0; py < 16; py += 3) {
    for (int px = 0; px < 24; px += 5) {
      const std::uint64_t pixel = static_cast<std::uint64_t>(py) * 24 + px;
      for (const int n : {8, 5}) {
        std::vector<SampleStream> batch, single;
        for (int i = 0; i < PathTracer::kCoherentSamples; ++i) {
          batch.emplace_back(1, pixel, static_cast<std::uint64_t>(i));
          single.emplace_back(1, pixel, static_cast<std::uint64_t>(i));
        }
        PixelSample together[PathTracer::kCoherentSamples];
        std::uint64_t batch_rays = 0, single_rays = 0;
        tracer.trace_coherent(px, py, batch.data(), n, together, batch_rays);
        for (int i = 0; i < n; ++i) {
          const PixelSample alone = tracer.trace(px, py, single[i], single_rays);
          expect_same(together[i], alone);
          lit += alone.radiance.maxCoeff() > 0.0f;
        }
        EXPECT_EQ(batch_rays, single_rays);
      }
    }
  }
  EXPECT_GT(lit, 100);
}

INSTANTIATE_TEST_SUITE_P(BothGeometries, CoherentRays,
                         ::testing::Values(TerrainGeometry::Grid, TerrainGeometry::HeightField));

}  // namespace
