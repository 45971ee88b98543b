// The ground's snow probability block by block (snow/occlusion_blocks.h): a
// raster split artificially into blocks that do not divide it gives the bits of
// one pass, with the halo the occlusion horizon needs, and the halo is what the
// header states (relief / drop lines, twice across, on every side).
#include "snow/occlusion_blocks.h"

#include <gtest/gtest.h>

#include <cmath>

#include "snow/snowfall_directions.h"
#include "snow/snowfall_probability.h"
#include "snow/snowfall_scene.h"
#include "tests/dem_fixture.h"

namespace {

using namespace drift::snow;

// Gentle waves with sharp towers (3 x 3 cells, 6-10 m high, every 23 cells):
// long shadows on 1 m cells, with a relief (~12 m) that keeps the halo a
// fraction of the raster, and shadows crossing the block edges.
drift::terrain::HeightField towers(int n) {
  drift::terrain::HeightField g(n, n, 0.0f, drift::terrain::local_georeference(1.0));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      g(x, y) = static_cast<float>(std::sin(x / 9.0) * std::cos(y / 13.0));
  for (int ty = 5; ty + 3 < n; ty += 23)
    for (int tx = 7; tx + 3 < n; tx += 23)
      for (int y = ty; y < ty + 3; ++y)
        for (int x = tx; x < tx + 3; ++x) g(x, y) += static_cast<float>(6 + (tx + ty) % 5);
  return g;
}

TEST(OcclusionBlocks, BlocksGiveTheBitsOfOnePass) {
  const SnowScene scene = make_snow_scene(towers(200), {}, 0.0);
  for (const double elevation : {35.0, 60.0}) {
    const auto dirs = jittered_directions(300.0, elevation, 8.0, 6, 1);
    const SnowProbability whole = snow_probability(scene, dirs);
    int shaded = 0;
    for (float v : whole.ground.values()) shaded += v < 0.5f;  // towers' shadows
    ASSERT_GT(shaded, 100) << "the test needs shadows";
    const int halo = occlusion_halo_cells(scene, dirs);
    std::printf("elevation %.0f: relief %.1f m, halo %d cells, %d cells shaded\n", elevation,
                static_cast<double>(scene.ground_hi - scene.ground_lo), halo, shaded);
    ASSERT_LT(halo, 120) << "the halo would hold the whole raster";
    for (const int block : {37, 64}) {
      const SnowProbability parts = ground_probability_in_blocks(scene, dirs, block);
      EXPECT_TRUE(parts.ground.values() == whole.ground.values()) << block;
      EXPECT_TRUE(parts.ground_facing.values() == whole.ground_facing.values()) << block;
    }
  }
}

TEST(OcclusionBlocks, HaloFollowsReliefOverTheDropPerLine) {
  const SnowScene scene = make_snow_scene(towers(64), {}, 0.0);
  const double relief = scene.ground_hi - scene.ground_lo;
  // Snow from due north at 45 degrees: lines are rows 1 m apart, 1 m of drop a line.
  const std::vector<FallDirection> north{{Eigen::Vector3d(0, 1, 1).normalized(), 1.0f, 0.0}};
  EXPECT_EQ(occlusion_halo_cells(scene, north), 2 * static_cast<int>(std::ceil(relief) + 1) + 3);
  // Straight down: nothing is occluded, only the normals' neighbours.
  const std::vector<FallDirection> down{{Eigen::Vector3d(0, 0, 1), 1.0f, 0.0}};
  EXPECT_EQ(occlusion_halo_cells(scene, down), 1);
}

}  // namespace
