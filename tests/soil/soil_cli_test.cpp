// drift soil: runs a scenario and writes the mesh, the VDB and the rasters;
// bad scenarios exit 1 and bad flags exit 2, naming what was wrong, and
// write nothing.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "terrain/mesh_io.h"
#include "terrain/raster_io.h"
#include "tests/dem_fixture.h"
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

// --vdb-frames writes a numbered VDB sequence (a volume sequence in Blender
// and Houdini), and two identical runs give the same bytes, frame for frame
// and for --vdb (before, OpenVDB's random UUID made every file differ).
TEST(SoilCli, VdbFramesAreASequenceAndRunsRepeatByteForByte) {
  const fs::path d = dir();
  std::ofstream(d / "s.toml") << kScenario;
  auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  std::string first[4];
  for (int runs = 0; runs < 2; ++runs) {
    fs::remove_all(d / "vdb");
    fs::create_directories(d / "vdb");
    ASSERT_EQ(run((d / "s.toml").string() + " -o " + (d / "soil.ply").string() + " --vdb " +
                      (d / "soil.vdb").string() + " --vdb-frames " + (d / "vdb").string() +
                      " --frame-every 20",
                  d),
              0)
        << output(d);
    const fs::path files[4] = {d / "vdb" / "soil_00020.vdb", d / "vdb" / "soil_00040.vdb",
                               d / "vdb" / "soil_00060.vdb", d / "soil.vdb"};
    for (int k = 0; k < 4; ++k) {
      ASSERT_TRUE(fs::exists(files[k])) << files[k];
      if (runs == 0) first[k] = bytes(files[k]);
      EXPECT_TRUE(first[k] == bytes(files[k])) << files[k] << " differs between runs";
    }
  }
  EXPECT_FALSE(first[0] == first[2]);  // the frames do change
}

TEST(SoilCli, DemGroundFollowsTheDemUpToTheWindowsEdges) {
  // A tilted plane of 10 m cells; a 6 x 4 window inside it split 4 x 4. The
  // ground under the grid is the DEM's bilinear surface, the plane itself, up
  // to its edges: they interpolate towards the pixels beyond the window (as the
  // renderer's surround does), not hold the edge pixel (2.5 m off there).
  const fs::path d = dir();
  const auto plane = [](double x, double y) { return 1000.0 + 0.8 * x - 0.3 * y; };
  drift::terrain::write_geotiff(drift::testing::dem_from(16, 10.0, 0.5, plane), d / "dem.tif");
  std::ofstream(d / "s.toml") << "[grid]\nsize = [0, 0, 40]\nvoxel = 2.5\n"
                                 "[terrain]\ndem = \"dem.tif\"\nwindow = [4, 5, 6, 4]\n"
                                 "upsample = 4\ndepth = 5\n[simulation]\nsteps = 0\n"
                                 // Some soil: a run without any is an error (no surface).
                                 "[[soil_body]]\non_ground = true\nposition = [30, 20, 4]\n"
                                 "[[soil_body.primitive]]\nshape = \"sphere\"\nradius = 6\n";
  ASSERT_EQ(run((d / "s.toml").string() + " -o " + (d / "soil.obj").string() + " --ground " +
                    (d / "ground.tif").string() + " --ground-margin 0",
                d),
            0)
      << output(d);
  const auto ground = drift::terrain::read_raster(d / "ground.tif");
  ASSERT_EQ(ground.width(), 24);
  ASSERT_EQ(ground.height(), 16);
  double worst = 0.0;
  for (int row = 0; row < ground.height(); ++row) {
    for (int x = 0; x < ground.width(); ++x) {
      // A DEM without a CRS: the grid's own frame, from the window's SW
      // corner (40 m east, 90 m south of the DEM's NW corner).
      const auto c = ground.geo().cell_center(x, row);
      worst = std::max(worst, std::abs(ground(x, row) - plane(40.0 + c[0], -90.0 + c[1])));
    }
  }
  EXPECT_LT(worst, 1e-3);
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
