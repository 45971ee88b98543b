// The snow-cover descriptor block by block (snow::snow_cover_to_files): its
// three outputs hold the bits of the one-pass descriptor (snow_cover on the
// whole DEM) at any block size and thread count, in every variant of the
// options; the halo is the least that does (one cell less breaks it); and
// the command line gives the one-pass cover with DRIFT_BLOCK_CELLS forced small.
#include <gdal.h>
#include <gtest/gtest.h>
#include <ogr_spatialref.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "snow/snow_cover.h"
#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/raster_io.h"
#include "tests/dem_fixture.h"
#include "tests/test_files.h"
#include "tests/utm_fixture.h"

using namespace drift::snow;
using drift::terrain::HeightField;
namespace fs = std::filesystem;

namespace {

using drift::testing::differing_cells;

fs::path dir() { return drift::testing::case_dir("drift_snow_cover_tiled"); }

// w x h cells of `cell` m in UTM (zone 33, north or south) of ridges, bowls
// and a plateau: heights with full float mantissas, concave and convex ground
// (finite and infinite TSA) and slopes facing every way. With base 0 the
// ground crosses sea level: heights of millimetres, whose float bits reach
// 2^-30 m, beside hundreds of metres, so that sums of rows in double round
// (and would round differently in a window starting elsewhere).
fs::path relief(int w, int h, double cell, bool south, const std::string& name,
                double base = 1800.0) {
  HeightField g(w, h, 0.0f, drift::terrain::local_georeference(cell));
  g.geo().crs_wkt = drift::testing::wkt_of_epsg(south ? 32733 : 32633);
  g.geo().geotransform = {500000.0, cell, 0.0, south ? 5200000.0 : 5100000.0, 0.0, -cell};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double e = x * cell, n = y * cell;
      double z = base + 420.0 * std::sin(e / 610.0) * std::cos(n / 470.0) +
                 95.0 * std::sin(e / 130.0 + n / 170.0) + 0.013 * e;
      if (std::hypot(e - 900.0, n - 700.0) < 250.0) z = std::min(z, 1900.0);  // a plateau
      g(x, y) = static_cast<float>(z);
    }
  const fs::path p = dir() / (name + ".tif");
  drift::terrain::write_geotiff(g, p, {"height", "m"});
  return p;
}

// Any float raster as it is (the TSA holds +inf, which read_raster refuses).
HeightField read_any(const fs::path& path) {
  GDALDatasetH ds = GDALOpen(path.c_str(), GA_ReadOnly);
  if (!ds) return {};
  const int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
  HeightField g(w, h);
  const CPLErr err = GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, 0, 0, w, h, g.data(), w, h,
                                  GDT_Float32, 0, 0);
  GDALClose(ds);
  return err == CE_None ? g : HeightField{};
}

// The tiled outputs at `block` against snow_cover on the whole DEM.
void expect_tiled_is_one_pass(const fs::path& dem_path, const CoverOptions& o, int block) {
  SCOPED_TRACE("block " + std::to_string(block));
  const HeightField dem = drift::terrain::read_raster(dem_path);
  const CoverResult one = snow_cover(dem, o);
  const fs::path c = dir() / "c.tif", t = dir() / "t.tif", a = dir() / "a.tif";
  const CoverFilesResult r = snow_cover_to_files({dem_path, c, t, a, block}, o);
  ASSERT_GT((r.width + block - 1) / block, 2) << "the DEM must be split";
  EXPECT_EQ(r.southern, one.southern);
  EXPECT_EQ(differing_cells(drift::terrain::read_raster(t), one.descriptor), 0);
  EXPECT_EQ(differing_cells(read_any(a), one.accessibility), 0);
  HeightField cover = one.descriptor;
  double mean = 0.0;
  for (float& v : cover.values()) v = 1.0f - v, mean += v;
  EXPECT_EQ(differing_cells(drift::terrain::read_raster(c), cover), 0);
  EXPECT_NEAR(r.mean_cover, mean / static_cast<double>(cover.size()), 1e-12);
}

CoverOptions quick() {  // the paper's cells on a 10 m DEM
  CoverOptions o;
  o.region_cells = 3;
  o.radius_cells = 5.5;
  return o;
}

}  // namespace

TEST(SnowCoverTiled, GivesTheOnePassBitsAtAnyBlockSize) {
  const fs::path dem = relief(157, 131, 9.973, false, "north");
  for (int block : {16, 37, 64}) expect_tiled_is_one_pass(dem, quick(), block);
  const fs::path coast = relief(157, 131, 9.973, false, "coast", 0.0);
  for (int block : {16, 50}) expect_tiled_is_one_pass(coast, quick(), block);
}

TEST(SnowCoverTiled, MudflatBesideACliffGivesTheOnePassBits) {
  // Heights of a tenth of a millimetre east of a 5 km cliff: a row's sums in
  // double from the west edge carry the cliff's 5e5 m and round at 2^-34 m,
  // a window east of the cliff does not: only exact sums agree.
  HeightField g(200, 90, 0.0f, drift::terrain::local_georeference(10.0));
  for (int y = 0; y < g.height(); ++y)
    for (int x = 0; x < g.width(); ++x)
      g(x, y) = x < 60 ? static_cast<float>(5000.0 + 7.3 * std::sin(x * 0.7 + y * 0.3))
                       : static_cast<float>(1e-4 * (1.3 + std::sin(x * 0.37) * std::cos(y * 0.29)));
  const fs::path p = dir() / "mudflat.tif";
  drift::terrain::write_geotiff(g, p, {"height", "m"});
  for (int block : {16, 40}) expect_tiled_is_one_pass(p, quick(), block);
}

TEST(SnowCoverTiled, MetricDefaultsSnowLineMeanSunAndSouth) {
  // The metric defaults on 25 m cells: region 6 cells, 5 passes, halo 33.
  const fs::path north = relief(150, 140, 25.0, false, "metric");
  expect_tiled_is_one_pass(north, CoverOptions{}, 40);
  CoverOptions o = quick();
  o.snow_line_m = 1850.0;
  o.sun_step = SunStep::Mean;
  o.floor = 0.2;
  const fs::path south = relief(121, 99, 10.0, true, "south");
  expect_tiled_is_one_pass(south, o, 24);
  o.sun_range_deg = 0.0;
  o.iterations = 0;
  expect_tiled_is_one_pass(south, o, 16);
}

TEST(SnowCoverTiled, SameBitsOnOneThread) {
  const fs::path dem = relief(120, 120, 10.0, false, "threads");
  const fs::path many = dir() / "many.tif", one = dir() / "one.tif";
  snow_cover_to_files({dem, many, {}, {}, 32}, quick());
  {
    tbb::global_control only(tbb::global_control::max_allowed_parallelism, 1);
    snow_cover_to_files({dem, one, {}, {}, 32}, quick());
  }
  EXPECT_EQ(differing_cells(drift::terrain::read_raster(many), drift::terrain::read_raster(one)),
            0);
}

namespace {

// Cells of the block [40, 80)^2 of `dem` whose descriptor, made from the window
// reaching `halo` cells around it, differs from the whole DEM's.
long block_cells_differing(const HeightField& dem, const CoverOptions& o, int halo) {
  const CoverResult whole = snow_cover(dem, o);
  const int x0 = 40 - halo, side = 40 + 2 * halo;
  HeightField window(side, side, 0.0f, dem.geo());
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) window(x, y) = dem(x0 + x, x0 + y);
  // The altitude factor needs the DEM's z_max: put the DEM's highest height
  // in the window's corner, which no block cell reads (L1 distance 2 halo).
  float z_max = -1e30f;
  for (float v : dem.values()) z_max = std::max(z_max, v);
  window(0, 0) = z_max;
  const CoverResult part = snow_cover(window, o);
  long differ = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) {
      const float a = part.descriptor(halo + x, halo + y), b = whole.descriptor(40 + x, 40 + y);
      differ += std::memcmp(&a, &b, sizeof a) != 0;
    }
  return differ;
}

}  // namespace

TEST(SnowCoverTiled, HaloIsWideEnoughAndNoWiderThanTheStepsReach) {
  // k n + 3: the smoothing passes, the normals and TSA, the smoothing of t.
  CoverOptions o = quick();
  EXPECT_EQ(cover_halo(o, 10.0), 5 * 3 + 3);
  EXPECT_EQ(cover_halo(CoverOptions{}, 1.0), 5 * 150 + 3) << "the metric defaults at 1 m";
  const HeightField dem = drift::terrain::read_raster(relief(120, 120, 10.0, false, "halo"));
  EXPECT_EQ(block_cells_differing(dem, o, cover_halo(o, 10.0)), 0);
  // The far cells of the smoothing weigh (1/48)^k: below a float's rounding
  // one cell short, but not two passes short.
  EXPECT_GT(block_cells_differing(dem, o, cover_halo(o, 10.0) - 2 * 3), 0);
  // Without smoothing the last 3 cells all count: one short changes bits.
  o.iterations = 0;
  EXPECT_EQ(cover_halo(o, 10.0), 3);
  EXPECT_EQ(block_cells_differing(dem, o, 3), 0);
  EXPECT_GT(block_cells_differing(dem, o, 2), 0) << "a halo one cell short gave the same bits";
}

TEST(SnowCoverTiled, CommandWithSmallBlocksGivesTheOnePassCover) {
  const fs::path dem = relief(140, 110, 10.0, false, "cli");
  const std::string drift = DRIFT_EXECUTABLE;
  const auto run = [&](const std::string& env, const fs::path& out) {
    const std::string cmd = env + " " + drift + " snow cover " + dem.string() +
                            " --region-cells 3 --radius-cells 5.5 -o " + out.string() +
                            " > /dev/null 2>&1";
    return std::system(cmd.c_str());
  };
  ASSERT_EQ(run("DRIFT_BLOCK_CELLS=16", dir() / "small.tif"), 0);
  ASSERT_EQ(run("", dir() / "whole.tif"), 0);
  EXPECT_EQ(differing_cells(drift::terrain::read_raster(dir() / "small.tif"),
                            drift::terrain::read_raster(dir() / "whole.tif")),
            0);
  EXPECT_NE(run("DRIFT_BLOCK_CELLS=7", dir() / "bad.tif"), 0) << "a block under 16 is refused";
  EXPECT_FALSE(fs::exists(dir() / "bad.tif"));
}

TEST(SnowCoverTiled, DefaultBlockIsFourHalosWithinMemory) {
  // The metric defaults on a 1 m DEM: a 753-cell halo, beside which the old
  // default block of 2048 was a third of its window (issue 36).
  const int halo = cover_halo(CoverOptions{}, 1.0);
  constexpr std::uint64_t kGiB = std::uint64_t{1} << 30;
  const auto window = [&](int block) {
    return (std::uint64_t(block) + 2 * halo) * (std::uint64_t(block) + 2 * halo) * 24;
  };
  const int roomy = default_cover_block(halo, 16 * kGiB);
  EXPECT_GE(roomy, 4 * halo);
  EXPECT_LT(roomy, 4 * halo + 256);
  EXPECT_EQ(roomy % 256, 0);
  EXPECT_EQ(default_cover_block(cover_halo(CoverOptions{}, 10.0), 16 * kGiB), kCoverBlock)
      << "a small halo keeps the 2048 block";
  // Bounded by memory: the window within half of what is available, never
  // below kCoverBlock.
  const int tight = default_cover_block(halo, 800u << 20);
  EXPECT_LT(tight, roomy);
  EXPECT_GE(tight, kCoverBlock);
  EXPECT_LE(window(tight), (800u << 20) / 2);
  EXPECT_GT(window(tight + 256), (800u << 20) / 2) << "shrunk no more than needed";
  EXPECT_EQ(default_cover_block(halo, 1u << 20), kCoverBlock);
  // The files' descriptor takes it when no block is given.
  const fs::path dem = relief(70, 60, 1.0, false, "one_metre");
  const fs::path c = dir() / "block_cover.tif";
  const CoverFilesResult r = snow_cover_to_files({dem, c, {}, {}, 0}, CoverOptions{});
  EXPECT_EQ(r.halo, halo);
  EXPECT_EQ(r.block, default_cover_block(halo, drift::available_memory_bytes()));
}
