// drift soil: runs a scenario and writes the mesh, the VDB and the rasters;
// bad scenarios exit 1 and bad flags exit 2, naming what was wrong, and
// write nothing.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "terrain/mesh_io.h"
#include "terrain/raster_io.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;

namespace {

fs::path dir() { return drift::testing::test_dir("drift_soil_cli"); }

// A small column of soil on a block.
const char* kScenario = R"([grid]
size = [24, 24, 24]
voxel = 0.1
[simulation]
steps = 60
[[body]]
name = "block"
position = [1.2, 1.2, 0.3]
[[body.primitive]]
shape = "cuboid"
half_extents = [0.4, 0.4, 0.3]
[[soil_body]]
[[soil_body.primitive]]
shape = "cylinder"
center = [1.2, 1.2, 1.4]
radius = 0.5
half_height = 0.4
)";

int run(const std::string& args, const fs::path& d) {
  return drift::testing::run_drift("soil " + args, d);
}

std::string output(const fs::path& d) { return drift::testing::drift_log(d); }

TEST(SoilCli, WritesMeshVdbSurfaceAndGround) {
  const fs::path d = dir();
  std::ofstream(d / "s.toml") << kScenario;
  ASSERT_EQ(run((d / "s.toml").string() + " -o " + (d / "soil.ply").string() + " --vdb " +
                    (d / "soil.vdb").string() + " --surface " + (d / "top.tif").string() +
                    " --ground " + (d / "ground.tif").string() + " --collision " +
                    (d / "bodies.obj").string() + " --soil loam --threads 2",
                d),
            0)
      << output(d);
  const drift::terrain::Mesh m = drift::terrain::read_ply(d / "soil.ply");
  EXPECT_GT(m.triangle_count(), 100u);
  ASSERT_NE(m.attribute("wetness"), nullptr);
  EXPECT_GT(fs::file_size(d / "soil.vdb"), 1000u);
  EXPECT_GT(fs::file_size(d / "bodies.obj"), 100u);
  // The top raster: the soil on the block stands above the block's 0.6 m.
  const auto top = drift::terrain::read_raster(d / "top.tif");
  EXPECT_EQ(top.width(), 24);
  EXPECT_GT(top(12, 12), 0.6f);
  EXPECT_EQ(drift::terrain::read_raster(d / "ground.tif").width(), 24 + 64);
}

TEST(SoilCli, BadScenariosAreErrorsNamingTheValueAndWriteNothing) {
  const fs::path d = dir();
  const std::string base = kScenario;
  const struct {
    std::string from, to, expect;
  } cases[] = {
      {"radius = 0.5", "radius = -0.5", "radius"},
      {"radius = 0.5", "radius = nan", "radius"},
      {"steps = 60", "steps = 60\nbogus = 1", "unknown key"},
      {"size = [24, 24, 24]", "size = [4000, 4000, 4000]", "soil grid 4000 x 4000 x 4000"},
      {"shape = \"cylinder\"", "shape = \"torus\"", "torus"},
  };
  for (const auto& c : cases) {
    std::string text = base;
    text.replace(text.find(c.from), c.from.size(), c.to);
    std::ofstream(d / "bad.toml") << text;
    EXPECT_EQ(run((d / "bad.toml").string() + " -o " + (d / "soil.ply").string(), d), 1)
        << c.to << ": " << output(d);
    EXPECT_NE(output(d).find(c.expect), std::string::npos) << output(d);
    EXPECT_FALSE(fs::exists(d / "soil.ply"));
  }
  std::ofstream(d / "s.toml") << kScenario;
  EXPECT_EQ(run((d / "s.toml").string() + " -o " + (d / "soil.ply").string() + " --soil clay", d),
            2);
  EXPECT_EQ(run((d / "s.toml").string() + " -o " + (d / "soil.ply").string() + " --phi 75", d), 2);
  EXPECT_EQ(run((d / "s.toml").string() + " -o " + (d / "soil.stl").string(), d), 2);
  EXPECT_FALSE(fs::exists(d / "soil.ply"));
}

}  // namespace
