// drift snow fall: writes the rasters (depth, cover, snow surface) and the snowy mesh; bad input
// exits 2 (usage) or 1 (files), naming what was wrong, and writes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "terrain/raster_io.h"
#include "tests/cli_fixture.h"
#include "tests/dem_fixture.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;

namespace {

fs::path dir() { return drift::testing::test_dir("drift_snowfall_cli"); }

// A small metric ground (UTM 53N) and an objects file with a rock on it.
fs::path setup(const fs::path& d) {
  drift::testing::write_flat_utm_ground(d, 40, 1500.0f, 0.5);
  std::ofstream(d / "objects.toml") << "[[objects]]\nmesh = \"" DRIFT_SOURCE_DIR
                                       "/data/objects/rock_b.obj\"\nposition = [600010.0, "
                                       "3999990.0, 1500.0]\n";
  return d / "ground.tif";
}

int run(const std::string& args, const fs::path& d) {
  return drift::testing::run_drift("snow fall " + args, d);
}

std::string output(const fs::path& d) { return drift::testing::drift_log(d); }

TEST(SnowfallCli, WritesDepthCoverSurfaceAndMesh) {
  const fs::path d = dir(), ground = setup(d);
  ASSERT_EQ(run(ground.string() + " --objects " + (d / "objects.toml").string() +
                    " --direction 45,70 --spread 5 --maps 4 --rate 0.01 --hours 20 -o " +
                    (d / "depth.tif").string() + " --cover " + (d / "cover.tif").string() +
                    " --surface " + (d / "surface.tif").string() + " --mesh-out " +
                    (d / "snowy.ply").string() + " --threads 1",
                d),
            0)
      << output(d);
  const auto depth = drift::terrain::read_raster(d / "depth.tif");
  EXPECT_EQ(depth.geo().geotransform[0], 600000.0);
  EXPECT_EQ(depth(2, 2), 0.2f);  // open flat ground: rate x hours
  EXPECT_TRUE(fs::exists(d / "cover.tif"));
  // The snow surface (docs/snowfall.md, `--surface`): ground + depth, same
  // georeference.
  const auto surface = drift::terrain::read_raster(d / "surface.tif");
  EXPECT_EQ(surface.geo().geotransform, depth.geo().geotransform);
  for (int row = 0; row < depth.height(); ++row)
    for (int x = 0; x < depth.width(); ++x)
      EXPECT_EQ(surface(x, row), 1500.0f + depth(x, row)) << x << "," << row;
  EXPECT_GT(fs::file_size(d / "snowy.ply"), 1000u);
  // The mesh is relative to the raster's central cell, in whole metres.
  EXPECT_NE(output(d).find("position = [600010, 3999990, 0]"), std::string::npos) << output(d);
}

// The ground's passes from the log line "stabilised in N passes on the ground".
int ground_passes(const std::string& log) {
  const std::string key = "stabilised in ";
  const auto at = log.rfind(key);
  return at == std::string::npos ? -1 : std::atoi(log.c_str() + at + key.size());
}

// Steep 96^2 mountains at UTM coordinates in D, and the arguments of a short
// snowfall on them up to "-o " (the two stabilisations' tests).
std::string mountains_run(const fs::path& d) {
  auto ground = drift::testing::snowfall_mountains(96);
  ground.geo().geotransform[0] = 600000.0, ground.geo().geotransform[3] = 4000000.0;
  drift::terrain::write_geotiff(ground, d / "ground.tif");
  return (d / "ground.tif").string() + " --maps 1 --rate 0.05 --hours 10 --threads 1 -o ";
}

// Gentle waves with 3 x 3 towers 8 m high every 23 cells, w x h cells of 1 m
// at UTM coordinates, written to D/ground.tif: long shadows and snow that
// slides off the towers, a relief (~10 m) whose occlusion halo (~33 cells at
// 35 degrees) is smaller than the raster. Returns the file.
fs::path write_towers_ground(const fs::path& d, int w, int h) {
  drift::terrain::HeightField ground(w, h, 0.0f, drift::terrain::local_georeference(1.0));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      ground(x, y) = static_cast<float>(std::sin(x / 9.0) * std::cos(y / 13.0) +
                                        ((x % 23 < 3 && y % 23 < 3) ? 8.0 : 0.0));
  ground.geo().geotransform[0] = 600000.0, ground.geo().geotransform[3] = 4000000.0;
  drift::terrain::write_geotiff(ground, d / "ground.tif");
  return d / "ground.tif";
}

double total(const drift::terrain::HeightField& f) {
  double sum = 0.0;
  for (float v : f.values()) sum += v;
  return sum;
}

// --coarse-levels reaches the ground's stabilisation (stabilise_grid.h): on
// steep mountains it settles in fewer passes on the grid, to another state
// holding the same snow.
TEST(SnowfallCli, CoarseLevelsStartTheGroundsStabilisation) {
  const fs::path d = dir();
  const std::string common = mountains_run(d);
  ASSERT_EQ(run(common + (d / "alone.tif").string(), d), 0) << output(d);
  const int alone = ground_passes(output(d));
  ASSERT_EQ(run(common + (d / "coarse.tif").string() + " --coarse-levels 1", d), 0) << output(d);
  const int coarse = ground_passes(output(d));
  EXPECT_GT(alone, 0);
  EXPECT_LT(coarse, alone);
  const auto a = drift::terrain::read_raster(d / "alone.tif");
  const auto c = drift::terrain::read_raster(d / "coarse.tif");
  EXPECT_NE(a.values(), c.values());
  EXPECT_NEAR(total(c), total(a), 1e-5 * total(a));
}

// --stabilise direct: the ground's snow at rest in one step (snow/stabilise_direct.h),
// the same snow as the passes leave, a different state; an unknown solver is a usage error.
TEST(SnowfallCli, StabiliseDirectSettlesTheSameSnowInOneStep) {
  const fs::path d = dir();
  const std::string common = mountains_run(d);
  ASSERT_EQ(run(common + (d / "passes.tif").string(), d), 0) << output(d);
  ASSERT_EQ(run(common + (d / "direct.tif").string() + " --stabilise direct", d), 0) << output(d);
  const auto a = drift::terrain::read_raster(d / "passes.tif");
  const auto c = drift::terrain::read_raster(d / "direct.tif");
  EXPECT_NE(a.values(), c.values());
  EXPECT_NEAR(total(c), total(a), 1e-5 * total(a));
  EXPECT_EQ(run(common + (d / "x.tif").string() + " --stabilise relax", d), 2);
  EXPECT_NE(output(d).find("--stabilise"), std::string::npos) << output(d);
}

// --direct-layers reaches the one-step solver: one layer and eight give
// different states holding the same snow; 0 layers is a usage error naming it.
TEST(SnowfallCli, DirectLayersReachTheOneStepSolver) {
  const fs::path d = dir();
  const std::string common = mountains_run(d);
  const std::string direct = " --stabilise direct --direct-layers ";
  ASSERT_EQ(run(common + (d / "one.tif").string() + direct + "1", d), 0) << output(d);
  ASSERT_EQ(run(common + (d / "eight.tif").string() + direct + "8", d), 0) << output(d);
  const auto a = drift::terrain::read_raster(d / "one.tif");
  const auto c = drift::terrain::read_raster(d / "eight.tif");
  EXPECT_NE(a.values(), c.values());
  EXPECT_NEAR(total(c), total(a), 1e-5 * total(a));
  EXPECT_EQ(run(common + (d / "x.tif").string() + direct + "0", d), 2);
  EXPECT_NE(output(d).find("--direct-layers"), std::string::npos) << output(d);
}

// --block: the ground's occlusion on blocks with their halo gives the bytes of one pass.
TEST(SnowfallCli, BlockByBlockOcclusionGivesTheSameRasters) {
  const fs::path d = dir();
  const std::string common =
      write_towers_ground(d, 160, 160).string() +
      " --direction 300,35 --spread 0 --maps 2 --rate 0.05 --hours 10 --threads 1 -o ";
  ASSERT_EQ(run(common + (d / "one.tif").string(), d), 0) << output(d);
  ASSERT_EQ(run(common + (d / "blocks.tif").string() + " --block 8", d), 0) << output(d);
  const auto a = drift::terrain::read_raster(d / "one.tif");
  const auto b = drift::terrain::read_raster(d / "blocks.tif");
  EXPECT_TRUE(a.values() == b.values());
  int shadowed = 0;  // cells with less than the open ground's snow (before sliding)
  for (float v : a.values()) shadowed += v < 0.25f;
  EXPECT_GT(shadowed, 200);
  EXPECT_EQ(run(common + (d / "x.tif").string() + " --block -3", d), 2);
  // A block past the grid is the grid: near INT_MAX its bounds overflowed and
  // an assertion aborted the run (exit 134).
  ASSERT_EQ(run(common + (d / "huge.tif").string() + " --block 2147483647", d), 0) << output(d);
  EXPECT_TRUE(a.values() == drift::terrain::read_raster(d / "huge.tif").values());
  // Where blocks do not apply, --block is refused rather than ignored.
  EXPECT_EQ(run(common + (d / "x.tif").string() + " --block 8 --occlusion opengl", d), 2);
  EXPECT_NE(output(d).find("--block works on the ground alone"), std::string::npos) << output(d);
  EXPECT_FALSE(fs::exists(d / "x.tif"));
}

// --block with --stabilise direct: the snow settled, read and written block
// by block (snow/snowfall_blocks.h) gives the rasters of one pass, bit for
// bit, though the towers' snow slides across the blocks' windows.
TEST(SnowfallCli, BlockByBlockStabilisationGivesTheSameRasters) {
  const fs::path d = dir();
  const std::string common =
      write_towers_ground(d, 90, 70).string() +
      " --direction 300,35 --spread 5 --maps 2 --rate 0.05 --hours 40 --stabilise direct -o ";
  auto rasters = [&](const std::string& name, const std::string& extra) {
    const std::string out = (d / name).string();
    EXPECT_EQ(
        run(common + out + ".tif --cover " + out + "_c.tif --surface " + out + "_s.tif" + extra, d),
        0)
        << output(d);
    std::vector<std::vector<float>> values;
    for (const char* part : {".tif", "_c.tif", "_s.tif"})
      values.push_back(drift::terrain::read_raster(d / (name + part)).values());
    return values;
  };
  const auto one = rasters("one", "");
  const auto blocks = rasters("blocks", " --block 16 --halo 2");
  EXPECT_EQ(output(d).find("(0 of the"), std::string::npos) << output(d);
  EXPECT_NE(output(d).find("windows worked again wider"), std::string::npos) << output(d);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(one[i].size(), 90u * 70u);
    EXPECT_TRUE(one[i] == blocks[i]) << "raster " << i << " differs";
  }
  EXPECT_EQ(run(common + (d / "x.tif").string() + " --halo 8", d), 2);  // needs --block
  EXPECT_NE(output(d).find("--halo works with --block"), std::string::npos) << output(d);
}

TEST(SnowfallCli, BadInputIsRefusedWithAMessageAndNoOutput) {
  const fs::path d = dir(), ground = setup(d);
  const std::string out = " -o " + (d / "depth.tif").string();
  EXPECT_EQ(run((d / "missing.tif").string() + out, d), 1);
  EXPECT_NE(output(d).find("missing.tif"), std::string::npos) << output(d);
  EXPECT_EQ(run(ground.string() + out + " --direction 45", d), 2);
  EXPECT_EQ(run(ground.string() + out + " --direction 45,0", d), 2);
  EXPECT_NE(output(d).find("--direction EL is 0; it must lie in (0, 90]"), std::string::npos)
      << output(d);
  EXPECT_EQ(run(ground.string() + out + " --maps 0", d), 2);
  EXPECT_EQ(run(ground.string() + out + " --spread -3", d), 2);
  EXPECT_EQ(run(ground.string() + out + " --occlusion raytrace", d), 2);
  for (const char* levels : {"-1", "17", "1.5", "nan", "one"}) {
    EXPECT_EQ(run(ground.string() + out + " --coarse-levels " + levels, d), 2) << levels;
    EXPECT_NE(output(d).find("--coarse-levels"), std::string::npos) << output(d);
  }
  EXPECT_EQ(run(ground.string() + out + " --mesh-out " + (d / "m.ply").string(), d), 2);
  // A stabilisation's setting given with the other stabilisation was ignored
  // (exit 0): refused, naming the flag.
  EXPECT_EQ(run(ground.string() + out + " --direct-layers 3", d), 2);
  EXPECT_NE(output(d).find("--direct-layers applies to --stabilise direct only"), std::string::npos)
      << output(d);
  EXPECT_EQ(run(ground.string() + out + " --stabilise direct --coarse-levels 2", d), 2);
  EXPECT_NE(output(d).find("--coarse-levels applies to --stabilise passes only"), std::string::npos)
      << output(d);
  EXPECT_FALSE(fs::exists(d / "depth.tif"));
  std::ofstream(d / "bad.toml") << "[[objects]]\nmesh = \"rock.obj\"\nsize = 2\n";
  EXPECT_EQ(run(ground.string() + out + " --objects " + (d / "bad.toml").string(), d), 1);
  EXPECT_NE(output(d).find("objects.size"), std::string::npos) << output(d);
  EXPECT_FALSE(fs::exists(d / "depth.tif"));
}

}  // namespace
