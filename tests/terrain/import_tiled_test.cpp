// drift import block by block (terrain::import_dem_to_file): the file it writes
// holds the bits of the one-pass import (import_dem) whatever the block size,
// through reprojection, crop, exaggeration and nodata gaps wider than any
// first halo; and the block size knob (DRIFT_BLOCK_CELLS) is checked.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>

#include "terrain/error.h"
#include "terrain/import.h"
#include "terrain/raster_blocks.h"
#include "terrain/raster_io.h"
#include "tests/dem_fixture.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using namespace drift::terrain;

namespace {

using drift::testing::differing_cells;

fs::path data(const char* name) { return fs::path(DRIFT_SOURCE_DIR) / "data" / name; }
fs::path dir() { return drift::testing::case_dir("drift_import_tiled"); }

// The one-pass import against the tiled one at `block`.
void expect_tiled_is_one_pass(const fs::path& dem, ImportOptions o, int block, const char* name) {
  SCOPED_TRACE(std::string(name) + " at block " + std::to_string(block));
  const ImportResult one = import_dem(dem, o);
  o.block = block;
  const fs::path out = dir() / (std::string(name) + "_" + std::to_string(block) + ".tif");
  const ImportFileResult tiled = import_dem_to_file(dem, out, o);
  const HeightField back = read_raster(out);
  EXPECT_EQ(differing_cells(one.grid, back), 0);
  EXPECT_EQ(tiled.filled_cells, one.filled_cells);
  EXPECT_EQ(back.geo().geotransform, one.grid.geo().geotransform);
  EXPECT_GT((tiled.width + block - 1) / block, 1) << "the raster must be split";
}

// n x n cells of 10 m in UTM 33N with nodata (-9999) in a square gap of `gap`
// cells a side centred at (cx, cy) and on a 3-cell-wide strip along row 5.
fs::path dem_with_gaps(int n, int gap, int cx, int cy) {
  HeightField g(n, n, 0.0f, local_georeference(10.0));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      g(x, y) = static_cast<float>(1200 + 300 * std::sin(x / 17.0) * std::cos(y / 23.0) + 0.37 * x -
                                   0.11 * y);
      if (std::abs(x - cx) <= gap / 2 && std::abs(y - cy) <= gap / 2) g(x, y) = NAN;
      if (y >= 4 && y <= 6 && x > n / 3) g(x, y) = NAN;
    }
  const fs::path p = dir() / ("gaps_" + std::to_string(gap) + ".tif");
  write_geotiff(g, p, {"height", "m"});
  return p;
}

}  // namespace

TEST(ImportTiled, GeographicDemWarpedToUtmGivesTheOnePassBits) {
  // Yarigatake: JGD2000 degrees -> UTM 53N, bilinear: the warp itself is split.
  for (int block : {64, 100}) {
    expect_tiled_is_one_pass(data("yarigatake_gsi_dem10b_jgd2000.tif"), {}, block, "yari");
  }
}

TEST(ImportTiled, NodataFilledAcrossBlocksGivesTheOnePassBits) {
  // St Helens: 4151 nodata cells, some in gaps wider than the first halo (8).
  ImportOptions o;
  o.exaggeration = 1.5;
  for (int block : {16, 50}) {
    expect_tiled_is_one_pass(data("mount_st_helens_usgs_30m.dem"), o, block, "helens");
  }
}

TEST(ImportTiled, WideGapGrowsTheHaloAndStillGivesTheOnePassBits) {
  // A 61-cell gap across a block corner: rings up to 31 deep, so the halo must
  // grow from 8 to 32 to 128; a block wholly inside the gap has no valid cell
  // in its first window at all.
  const fs::path dem = dem_with_gaps(160, 61, 64, 64);
  ImportOptions o;
  o.block = 16;
  const ImportFileResult r = import_dem_to_file(dem, dir() / "wide.tif", o);
  EXPECT_GE(r.max_fill_halo, 32);
  expect_tiled_is_one_pass(dem, {}, 16, "wide");
  expect_tiled_is_one_pass(dem, {}, 40, "wide");
}

TEST(ImportTiled, CropIsTiledToo) {
  const ImportResult full = import_dem(data("mount_st_helens_usgs_30m.dem"), {});
  const auto& gt = full.grid.geo().geotransform;
  ImportOptions o;
  o.crop = std::array<double, 4>{gt[0] + 1800.0, gt[3] - 9000.0, gt[0] + 6000.0, gt[3] - 2700.0};
  o.resample_m = 20.0;
  expect_tiled_is_one_pass(data("mount_st_helens_usgs_30m.dem"), o, 48, "crop");
}

TEST(ImportTiled, AllNodataIsAnErrorAndWritesNothing) {
  HeightField g(40, 40, NAN, local_georeference(10.0));
  const fs::path p = dir() / "empty.tif", out = dir() / "empty_out.tif";
  write_geotiff(g, p, {"height", "m"});
  fs::remove(out);
  ImportOptions o;
  o.block = 16;
  try {
    import_dem_to_file(p, out, o);
    FAIL() << "expected an error";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("holds no valid height"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out));
}

TEST(ImportTiled, BlockSizeKnob) {
  unsetenv("DRIFT_BLOCK_CELLS");
  EXPECT_EQ(block_cells(0, 2048), 2048);
  EXPECT_EQ(block_cells(64, 2048), 64);
  setenv("DRIFT_BLOCK_CELLS", "32", 1);
  EXPECT_EQ(block_cells(0, 2048), 32);
  EXPECT_EQ(block_cells(64, 2048), 64) << "an explicit block wins";
  for (const char* bad : {"8", "12x", "-64", "abc", "99999999999"}) {
    setenv("DRIFT_BLOCK_CELLS", bad, 1);
    EXPECT_THROW(block_cells(0, 2048), drift::Error) << bad;
  }
  unsetenv("DRIFT_BLOCK_CELLS");
}
