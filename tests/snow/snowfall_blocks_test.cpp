// Snowfall block by block (snow/snowfall_blocks.h): the rasters of one pass
// (simulate_snowfall with the one-step stabilisation), bit for bit, with the
// raster split into small blocks, including snow that slides across several.
#include "snow/snowfall_blocks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

#include "snow/snowfall.h"
#include "terrain/height_change.h"
#include "terrain/raster_io.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
namespace snow = drift::snow;
using drift::terrain::HeightField;

namespace {

HeightField ground_of(int w, int h, const std::function<double(int, int)>& z) {
  HeightField g(w, h, 0.0f, drift::terrain::local_georeference(1.0));
  g.geo().geotransform[0] = 600000.0, g.geo().geotransform[3] = 4000000.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) g(x, y) = static_cast<float>(z(x, y));
  return g;
}

snow::SnowfallOptions options() {
  snow::SnowfallOptions o;
  o.azimuth_deg = 300, o.elevation_deg = 60, o.spread_deg = 5, o.maps = 2;
  o.rate_m_per_h = 0.05, o.hours = 10;
  o.direct_stabilise = true;  // the default 4 layers
  return o;
}

// Runs the blocks on `ground` and expects the rasters of one pass, bit for bit.
snow::SnowfallBlockReport expect_one_pass(const HeightField& ground, const snow::SnowfallOptions& o,
                                          int block, int halo, const std::string& name) {
  const fs::path d = drift::testing::test_dir("drift_snowfall_blocks");
  drift::terrain::write_geotiff(ground, d / (name + "_ground.tif"));
  const drift::snow::SnowfallResult one = drift::snow::simulate_snowfall(ground, {}, o);
  snow::SnowfallBlockFiles files{d / (name + "_ground.tif"),
                                 d / (name + "_depth.tif"),
                                 d / (name + "_cover.tif"),
                                 d / (name + "_surface.tif"),
                                 block,
                                 halo};
  const snow::SnowfallBlockReport r = drift::snow::snowfall_to_files(files, o);
  std::printf("%s: %d blocks, %d of them widened, %d doublings, largest halo %d\n", name.c_str(),
              r.blocks, r.windows_widened, r.widened, r.largest_halo);
  // Each widened window doubled at least once: as many doublings as windows or more.
  EXPECT_LE(r.windows_widened, r.blocks);
  EXPECT_LE(r.windows_widened, r.widened);
  EXPECT_EQ(r.windows_widened > 0, r.widened > 0);
  const HeightField depth = drift::terrain::read_raster(files.depth);
  const HeightField cover = drift::terrain::read_raster(files.cover);
  const HeightField surface = drift::terrain::read_raster(files.surface);
  const HeightField top = drift::terrain::lay_on_ground(ground, one.depth);
  int differ = 0;
  double worst = 0;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    const float a = one.depth.values()[i], b = depth.values()[i];
    if (std::isnan(a) && std::isnan(b)) continue;
    if (a != b) ++differ, worst = std::max(worst, std::abs(double(a) - b));
  }
  EXPECT_EQ(differ, 0) << "cells whose depth differs from one pass, by up to " << worst << " m";
  for (std::size_t i = 0; i < depth.size(); ++i) {
    const float a = one.coverage.values()[i], b = cover.values()[i];
    const float s = top.values()[i], t = surface.values()[i];
    if (!(std::isnan(a) && std::isnan(b))) {
      EXPECT_EQ(a, b) << "cover, cell " << i;
    }
    if (!(std::isnan(s) && std::isnan(t))) {
      EXPECT_EQ(s, t) << "surface, cell " << i;
    }
    if (::testing::Test::HasFailure()) break;
  }
  EXPECT_EQ(r.blocks,
            ((ground.width() + block - 1) / block) * ((ground.height() + block - 1) / block));
  EXPECT_NEAR(r.ground_volume, one.ground_volume, 1e-9 * one.ground_volume);
  EXPECT_NEAR(r.fallen_volume, one.fallen_volume, 1e-9 * one.fallen_volume);
  return r;
}

}  // namespace

// Gentle waves with steep pits and towers where snow slides and heaps, and
// a few nodata cells, on a raster not a multiple of the block.
TEST(SnowfallBlocks, SameRastersAsOnePass) {
  const HeightField g = ground_of(150, 131, [](int x, int y) {
    double z = 3.0 * std::sin(x / 11.0) * std::cos(y / 7.0);
    if (x % 37 > 30 && y % 29 > 24) z += 6.0;                      // towers: their snow slides off
    if ((x - 70) * (x - 70) + (y - 60) * (y - 60) < 30) z -= 8.0;  // a pit the snow fills
    return z;
  });
  HeightField holes = g;
  holes(5, 100) = holes(6, 100) = holes(120, 3) = std::nanf("");
  const snow::SnowfallBlockReport r = expect_one_pass(holes, options(), 32, 4, "waves");
  EXPECT_GT(r.widened, 0) << "a 4-cell halo is too small for the towers' heaps";
  snow::SnowfallOptions one_layer = options();
  one_layer.direct_layers = 1;
  expect_one_pass(g, one_layer, 40, 8, "waves1");
}

// A 60-degree slope 90 cells long across blocks of 16: its snow runs down
// over five blocks to the floor, so the halo must grow far beyond its first
// 4 cells; the checks catch it (with either check left out, some cells of
// the floor differ from one pass).
TEST(SnowfallBlocks, SnowSlidingAcrossSeveralBlocks) {
  const double rise = std::tan(60.0 * M_PI / 180.0);
  const HeightField g = ground_of(120, 40, [&](int x, int y) {
    const double slope = x < 90 ? (90 - x) * rise : 0.0;
    return slope + 0.02 * std::sin(y / 3.0);
  });
  snow::SnowfallOptions o = options();
  o.elevation_deg = 90, o.spread_deg = 0, o.maps = 1;
  const snow::SnowfallBlockReport r = expect_one_pass(g, o, 16, 4, "slope");
  EXPECT_GE(r.largest_halo, 64) << "the slope's snow crosses several blocks";
}

// A steep pyramid in the middle block of three on flat ground: its snow (8
// m) slides to its foot, 4 cells from the block's edges, and the deposit
// spreads over the neighbouring blocks' flat ground further than the first
// halo (4 cells), where their own windows see nothing move. The check from
// outside is what catches it there: left out, the neighbours' cells miss the
// deposit (depths off by up to 5.0 m; the middle block's own check widens
// its window once). With the block's own check left out, the one from
// outside still catches it, through the neighbours' widened windows.
TEST(SnowfallBlocks, DepositSpreadingOutOfItsBlock) {
  const double rise = std::tan(60.0 * M_PI / 180.0);
  const HeightField g = ground_of(192, 64, [&](int x, int y) {
    const double r = std::max(std::abs(x - 95.5), std::abs(y - 31.5));
    return r < 28 ? (28 - r) * rise : 0.0;
  });
  snow::SnowfallOptions o = options();
  o.elevation_deg = 90, o.spread_deg = 0, o.maps = 1, o.hours = 160;
  const snow::SnowfallBlockReport r = expect_one_pass(g, o, 64, 4, "pyramid");
  EXPECT_GT(r.widened, 0);
}
