// drift marks: writes the marked ground, the disturbance raster and frames;
// bad track files and keyframes exit 1 naming the file, line and value, and
// write nothing.
#include <gdal_priv.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "terrain/mesh_io.h"
#include "terrain/raster_io.h"
#include "tests/cli_fixture.h"
#include "tests/dem_fixture.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;

namespace {

fs::path dir() { return drift::testing::test_dir("drift_marks_cli"); }

// A flat metric ground (1 cm cells, UTM-sized coordinates) at 2000 m.
fs::path ground(const fs::path& d) {
  return drift::testing::write_flat_utm_ground(d, 64, 2000.0f, 0.01);
}

// A ball pressed 3 cm into the ground's middle and lifted again.
std::string track(const std::string& keyframes_extra = "", const std::string& top = "") {
  return "step = 0.1\n" + top +
         "[[objects]]\nmesh = \"" DRIFT_SOURCE_DIR
         "/data/objects/ball.obj\"\n"
         "scale = 0.5\n"
         "[[objects.keyframes]]\ntime = 0.0\nposition = [600000.32, 3999999.68, 2000.08]\n"
         "[[objects.keyframes]]\ntime = 0.3\nposition = [600000.32, 3999999.68, 2000.02]\n"
         "[[objects.keyframes]]\ntime = 0.5\nposition = [600000.32, 3999999.68, 2000.1]\n" +
         keyframes_extra;
}

int run(const std::string& args, const fs::path& d) {
  return drift::testing::run_drift("marks " + args, d);
}

std::string output(const fs::path& d) { return drift::testing::drift_log(d); }

TEST(MarksCli, WritesTheMarkedGroundDisturbanceAndFrames) {
  const fs::path d = dir(), g = ground(d);
  std::ofstream(d / "track.toml") << track();
  ASSERT_EQ(run(g.string() + " --track " + (d / "track.toml").string() + " -o " +
                    (d / "out.tif").string() + " --disturbed " + (d / "dist.tif").string() +
                    " --frames " + (d / "frames").string() + " --material snow",
                d),
            0)
      << output(d);
  const auto out = drift::terrain::read_raster(d / "out.tif");
  EXPECT_EQ(out.geo().geotransform[0], 600000.0);
  // Snow: compressed 3 cm under the ball's bottom (1 cm tessellation allowance).
  EXPECT_NEAR(out(32, 32), 2000.0f - 0.03f, 0.002f);
  EXPECT_LE(out(5, 5), 2000.0f);
  const auto dist = drift::terrain::read_raster(d / "dist.tif");
  EXPECT_NEAR(dist(32, 32), 0.03f, 0.002f);
  EXPECT_EQ(dist(2, 2), 0.0f);
  EXPECT_TRUE(fs::exists(d / "frames" / "frame_00000.tif"));
  EXPECT_TRUE(fs::exists(d / "frames" / "frame_00005.tif"));
}

// Issue 32 item 7: --posed writes the objects where the track's keyframes put
// them at --posed-at (default: the last keyframe), from the raster's
// north-west corner, so a scene shows the mark with the thing that made it.
TEST(MarksCli, PosedWritesTheObjectAtItsPoseAtAChosenTime) {
  const fs::path d = dir(), g = ground(d);
  std::ofstream(d / "track.toml") << track();
  for (const char* at : {"", " --posed-at 0.3"}) {
    ASSERT_EQ(run(g.string() + " --track " + (d / "track.toml").string() + " -o " +
                      (d / "out.tif").string() + " --posed " + (d / "ball.obj").string() + at,
                  d),
              0)
        << output(d);
    const drift::terrain::Mesh m = drift::terrain::read_obj(d / "ball.obj");
    ASSERT_FALSE(m.positions.empty());
    Eigen::Vector3f lo = m.positions[0], hi = m.positions[0];
    for (const auto& p : m.positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    // The ground's corner is (600000, 4000000); the ball (radius 5 cm) is
    // centred at (0.32, -0.32) from it, at 2000.1 m at the end, 2000.02 at 0.3 s.
    const Eigen::Vector3f centre = 0.5f * (lo + hi);
    EXPECT_NEAR(centre.x(), 0.32f, 1e-3f);
    EXPECT_NEAR(centre.y(), -0.32f, 1e-3f);
    EXPECT_NEAR(centre.z(), *at ? 2000.02f : 2000.1f, 1e-3f);
    EXPECT_NEAR(hi.x() - lo.x(), 0.1f, 2e-3f);
  }
}

TEST(MarksCli, BadTrackFilesExitOneNamingTheProblemAndWriteNothing) {
  const fs::path d = dir(), g = ground(d);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {track("[[objects.keyframes]]\ntime = 0.2\nposition = [600000.3, 3999999.6, 2000.0]\n"),
       "not after the keyframe before it"},
      {track("", "material = \"gravel\"\n"), "known materials: sand, mud, snow"},
      {"step = 0.1\n[[objects]]\nmesh = \"missing.obj\"\n[[objects.keyframes]]\ntime = 0\n"
       "position = [0, 0, 0]\n",
       "missing.obj"},
      {track("", "wind = 3\n"), "unknown key 'wind'"},
      {"step = 0.1\n[[objects]]\nmesh = \"" DRIFT_SOURCE_DIR "/data/objects/ball.obj\"\n",
       "needs keyframes"},
      {track().replace(track().find("2000.08"), 7, "nan"), "objects.keyframes.position"},
  };
  for (const auto& [text, message] : cases) {
    std::ofstream(d / "track.toml") << text;
    EXPECT_EQ(run(g.string() + " --track " + (d / "track.toml").string() + " -o " +
                      (d / "out.tif").string(),
                  d),
              1)
        << text;
    EXPECT_NE(output(d).find(message), std::string::npos) << output(d);
    EXPECT_FALSE(fs::exists(d / "out.tif"));
  }
}

// Refused like any output that is an input (docs/outputs.md): exit 1.
TEST(MarksCli, AnOutputThatIsAnInputIsRefused) {
  const fs::path d = dir(), g = ground(d);
  std::ofstream(d / "track.toml") << track();
  EXPECT_EQ(run(g.string() + " --track " + (d / "track.toml").string() + " -o " + g.string(), d), 1)
      << output(d);
}

// Issue 32 item 6: a track whose object never touches the ground (a typo in a
// height: 1 m too high) warns, naming the object and its lowest point against
// the ground beneath, and the run says how many steps had contact.
TEST(MarksCli, AnObjectThatNeverTouchesTheGroundIsNamed) {
  const fs::path d = dir(), g = ground(d);
  std::string text = track();
  for (const char* z : {"2000.08", "2000.02", "2000.1"}) {
    const std::string high = std::to_string(std::stod(z) + 1.0).substr(0, 7);
    text.replace(text.find(z), std::string(z).size(), high);
  }
  std::ofstream(d / "track.toml") << text;
  ASSERT_EQ(run(g.string() + " --track " + (d / "track.toml").string() + " -o " +
                    (d / "out.tif").string(),
                d),
            0)
      << output(d);
  const std::string log = output(d);
  EXPECT_NE(log.find("warning: object 1 (ball.obj) never touches the ground"), std::string::npos)
      << log;
  // The ball's lowest vertex against the ground (tessellation: 0.97 to 0.971).
  EXPECT_NE(log.find("no nearer than 0.97"), std::string::npos) << log;
  EXPECT_NE(log.find("m above the ground beneath it"), std::string::npos) << log;
  EXPECT_NE(log.find("6 steps, 0 with contact"), std::string::npos) << log;
  // A track that presses says so, without a warning.
  std::ofstream(d / "track.toml") << track();
  ASSERT_EQ(run(g.string() + " --track " + (d / "track.toml").string() + " -o " +
                    (d / "out.tif").string(),
                d),
            0);
  EXPECT_EQ(output(d).find("warning"), std::string::npos) << output(d);
  EXPECT_NE(output(d).find("6 steps, 3 with contact"), std::string::npos) << output(d);
}

// --materials: the ground's material per cell (0 sand, 1 mud, 2 snow); a cell
// holding anything else exits 1 naming the file, the cell and the value, and
// writes nothing.
TEST(MarksCli, AMaterialRasterSetsTheGroundsMaterialPerCell) {
  const fs::path d = dir(), g = ground(d);
  std::ofstream(d / "track.toml") << track();
  auto painted = drift::testing::flat_utm_ground(64, 2.0f, 0.01);  // all snow
  drift::terrain::write_geotiff(painted, d / "paint.tif");
  const std::string args = g.string() + " --track " + (d / "track.toml").string() + " -o " +
                           (d / "out.tif").string() + " --materials " + (d / "paint.tif").string();
  ASSERT_EQ(run(args, d), 0) << output(d);
  const auto out = drift::terrain::read_raster(d / "out.tif");
  float top = -1e9f;
  for (float v : out.values()) top = std::max(top, v);
  EXPECT_LE(top, 2000.0f) << "snow: compressed, no rim";
  painted(9, 4) = 7.0f;
  drift::terrain::write_geotiff(painted, d / "paint.tif");
  fs::remove(d / "out.tif");
  EXPECT_EQ(run(args, d), 1) << output(d);
  EXPECT_NE(output(d).find("paint.tif': cell (9, 4) holds 7"), std::string::npos) << output(d);
  EXPECT_FALSE(fs::exists(d / "out.tif"));
  // 1e30 and inf are no material: named as such, with the value as given and
  // the fix (they were refused as "a height beyond any ground").
  for (const float bad : {1e30f, std::numeric_limits<float>::infinity()}) {
    painted(9, 4) = bad;
    drift::terrain::write_geotiff(painted, d / "paint.tif");
    EXPECT_EQ(run(args, d), 1) << output(d);
    const std::string said = bad > 1e31f ? "holds inf;" : "holds 1e+30;";
    EXPECT_NE(output(d).find(std::string("material raster '") + (d / "paint.tif").string() +
                             "': cell (9, 4) " + said +
                             " each cell must hold a whole number from 0 to 2"),
              std::string::npos)
        << output(d);
    EXPECT_EQ(output(d).find("height"), std::string::npos) << output(d);
    EXPECT_FALSE(fs::exists(d / "out.tif"));
  }
  // Three bands: refused naming the count, not read as band 1.
  GDALAllRegister();
  GDALDataset* rgb = GetGDALDriverManager()->GetDriverByName("GTiff")->Create(
      (d / "paint.tif").string().c_str(), 64, 64, 3, GDT_Float32, nullptr);
  ASSERT_NE(rgb, nullptr);
  GDALClose(rgb);
  EXPECT_EQ(run(args, d), 1) << output(d);
  EXPECT_NE(output(d).find("paint.tif' has 3 bands"), std::string::npos) << output(d);
  EXPECT_FALSE(fs::exists(d / "out.tif"));
}

TEST(MarksCli, FramesDoNotOverwriteTheRunsOtherFiles) {
  // --frames DIR writes DIR/frame_NNNNN.tif a step: another output or an
  // input named so there was written over by a frame (or wrote over it), exit 0.
  const fs::path d = dir(), g = ground(d);
  std::ofstream(d / "track.toml") << track();
  fs::create_directories(d / "fr");
  const std::string base =
      g.string() + " --track " + (d / "track.toml").string() + " --frames " + (d / "fr").string();
  for (const std::string& extra :
       {std::string(" -o ") + (d / "out.tif").string() + " --disturbed " +
            (d / "fr" / "frame_00001.tif").string(),
        std::string(" -o ") + (d / "fr" / ".." / "fr" / "frame_00000.tif").string()}) {
    SCOPED_TRACE(extra);
    EXPECT_EQ(run(base + extra, d), 1) << output(d);
    EXPECT_NE(output(d).find("is named like the frames --frames"), std::string::npos) << output(d);
    EXPECT_TRUE(fs::is_empty(d / "fr")) << "nothing written";
    EXPECT_FALSE(fs::exists(d / "out.tif"));
  }
  // An input there: the frames would write over the ground they mark.
  fs::copy_file(g, d / "fr" / "frame_00002.tif");
  EXPECT_EQ(
      run((d / "fr" / "frame_00002.tif").string() + " --track " + (d / "track.toml").string() +
              " --frames " + (d / "fr").string() + " -o " + (d / "out.tif").string(),
          d),
      1)
      << output(d);
  EXPECT_NE(output(d).find("frame_00002.tif' is named like the frames"), std::string::npos)
      << output(d);
  // Elsewhere, or named otherwise, the frames and the outputs stand side by side.
  EXPECT_EQ(run(base + " -o " + (d / "fr" / "marked.tif").string(), d), 0) << output(d);
  EXPECT_TRUE(fs::exists(d / "fr" / "frame_00001.tif"));
  EXPECT_TRUE(fs::exists(d / "fr" / "marked.tif"));
}

}  // namespace

namespace {

// Issue 36 item 3: --block reads, marks and writes the ground 16 cells at a
// time (UTM-sized coordinates: the windows place the ball in the raster's
// cells) and writes the one-pass run's heights bit for bit; with an option it
// cannot honour it exits 2 and writes nothing.
TEST(MarksCli, BlocksGiveTheOnePassGroundAndRefuseWhatTheyCannotDo) {
  const fs::path d = dir(), g = ground(d);
  std::ofstream(d / "track.toml") << track();
  const std::string common = g.string() + " --track " + (d / "track.toml").string();
  ASSERT_EQ(run(common + " -o " + (d / "one.tif").string(), d), 0) << output(d);
  // The one pass's summary: steps, contact steps and volumes.
  const std::string said = output(d);
  const std::size_t end = said.find(" away", said.rfind("with contact"));
  ASSERT_NE(end, std::string::npos) << said;
  const std::size_t from = said.rfind("marks: ", end);
  const std::string summary = said.substr(from, end - from);
  ASSERT_EQ(run(common + " -o " + (d / "blocks.tif").string() + " --block 16 --halo 8", d), 0)
      << output(d);
  EXPECT_NE(output(d).find("blocks of 16 cells worked"), std::string::npos) << output(d);
  // Block by block, the same figures (each step once, not the busiest block's).
  EXPECT_NE(output(d).find(summary), std::string::npos) << summary << "\n" << output(d);
  const auto one = drift::terrain::read_raster(d / "one.tif");
  const auto blocks = drift::terrain::read_raster(d / "blocks.tif");
  ASSERT_EQ(one.values().size(), blocks.values().size());
  EXPECT_TRUE(std::equal(one.values().begin(), one.values().end(), blocks.values().begin(),
                         [](float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }));
  EXPECT_LT(one(32, 32), 2000.0f - 0.02f);  // the ball pressed it
  EXPECT_EQ(run(common + " -o " + (d / "f.tif").string() + " --block 16 --frames " +
                    (d / "frames").string(),
                d),
            2)
      << output(d);
  EXPECT_NE(output(d).find("no step's field is ever whole"), std::string::npos) << output(d);
  EXPECT_FALSE(fs::exists(d / "f.tif"));
  // --halo without --block was ignored (exit 0): refused, naming the flag.
  EXPECT_EQ(run(common + " -o " + (d / "h.tif").string() + " --halo 5", d), 2) << output(d);
  EXPECT_NE(output(d).find("--halo applies to --block only"), std::string::npos) << output(d);
  EXPECT_FALSE(fs::exists(d / "h.tif"));
}

}  // namespace
