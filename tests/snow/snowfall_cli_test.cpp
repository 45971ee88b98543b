// drift snow fall: writes the rasters (depth, cover, snow surface) and the snowy mesh; bad input
// exits 2 (usage) or 1 (files), naming what was wrong, and writes nothing.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "terrain/raster_io.h"
#include "tests/dem_fixture.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;

namespace {

fs::path dir() { return drift::testing::test_dir("drift_snowfall_cli"); }

// A small metric ground (UTM 53N) and an objects file with a rock on it.
fs::path setup(const fs::path& d) {
  drift::terrain::write_geotiff(drift::testing::flat_utm_ground(40, 1500.0f, 0.5),
                                d / "ground.tif");
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
  // The snow surface (SPEC 3a): ground + depth, same georeference.
  const auto surface = drift::terrain::read_raster(d / "surface.tif");
  EXPECT_EQ(surface.geo().geotransform, depth.geo().geotransform);
  for (int row = 0; row < depth.height(); ++row)
    for (int x = 0; x < depth.width(); ++x)
      EXPECT_EQ(surface(x, row), 1500.0f + depth(x, row)) << x << "," << row;
  EXPECT_GT(fs::file_size(d / "snowy.ply"), 1000u);
  // The mesh is relative to the raster's central cell, in whole metres.
  EXPECT_NE(output(d).find("position = [600010, 3999990, 0]"), std::string::npos) << output(d);
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
  EXPECT_EQ(run(ground.string() + out + " --mesh-out " + (d / "m.ply").string(), d), 2);
  std::ofstream(d / "bad.toml") << "[[objects]]\nmesh = \"rock.obj\"\nsize = 2\n";
  EXPECT_EQ(run(ground.string() + out + " --objects " + (d / "bad.toml").string(), d), 1);
  EXPECT_NE(output(d).find("objects.size"), std::string::npos) << output(d);
  EXPECT_FALSE(fs::exists(d / "depth.tif"));
}

}  // namespace
