// `make -C data/scenes marks_sequence` (issue 37 item 5): a marks run's frames
// rendered one image each under a camera that does not move while the ground
// does. Run through make itself, short and small (2 frames at 64x40, 1 spp).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "render/image_io.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using drift::testing::slurp;
using drift::testing::test_dir;

namespace {

// The sidecar's "camera" object: position, rotation and world_to_camera.
std::string camera_of(const std::string& json) {
  const auto at = json.find("\"camera\":");
  const auto end = json.find("\"sun\":", at);
  return at == std::string::npos || end == std::string::npos ? "" : json.substr(at, end - at);
}

// Every number in `text`, in order.
std::vector<double> numbers(const std::string& text) {
  std::vector<double> out;
  const std::regex number(R"([-+]?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), number);
       it != std::sregex_iterator(); ++it)
    out.push_back(std::stod(it->str()));
  return out;
}

}  // namespace

TEST(MarksSequence, ShortSequenceRendersThroughMakeWithTheCameraFixed) {
  const fs::path d = test_dir("marks_sequence");
  const std::string cmd =
      "make -C " DRIFT_SOURCE_DIR "/data/scenes marks_sequence OUT=" + d.string() +
      " DRIFT=" DRIFT_EXECUTABLE +
      " SEQ_FRAMES='00000 00030' SEQ='--size 64x40 --spp 1 --exposure 1.1'"
      " THREADS=2 > " +
      (d / "make.txt").string() + " 2>&1";
  const int raw = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << slurp(d / "make.txt");
  const fs::path seq = d / "marks_sequence";
  for (const char* f : {"frame_00000", "frame_00030"}) {
    EXPECT_TRUE(fs::exists(seq / (std::string(f) + ".png"))) << f;
    EXPECT_TRUE(fs::exists(seq / "frames" / (std::string(f) + ".tif"))) << f;
  }
  EXPECT_TRUE(fs::exists(d / "marks_sequence.png"));
  // The camera is the same in both frames: pose and world_to_camera within
  // 1e-6 (the eye is kept in float relative to the scene's origin, which
  // follows the ground: 3e-8 m apart here). A camera that moved by a
  // millimetre, or re-aimed by a microradian, fails.
  const std::vector<double> first = numbers(camera_of(slurp(seq / "frame_00000.json"))),
                            last = numbers(camera_of(slurp(seq / "frame_00030.json")));
  ASSERT_EQ(first.size(), 3u + 9u + 16u);
  ASSERT_EQ(first.size(), last.size());
  for (std::size_t i = 0; i < first.size(); ++i) EXPECT_NEAR(first[i], last[i], 1e-6) << i;
  // The ground changed under it: the ball's trough covers a good part of the view.
  const drift::render::Image a = drift::render::read_image(seq / "frame_00000.png"),
                             b = drift::render::read_image(seq / "frame_00030.png");
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  std::size_t changed = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    changed += std::abs(a.pixels[i] - b.pixels[i]) > 0.05f;
  EXPECT_GT(changed, a.pixels.size() / 20) << changed << " of " << a.pixels.size() << " values";
}

// `make -C data/scenes soil_sequence`: a soil run's frames (drift soil
// --frames, a surface mesh every 20 steps) each rendered as the scene's
// object under the fixed camera of soil_sequence.toml. Short: 40 steps, 2
// frames at 64x40, 1 spp. The camera is the same, the soil moved.
TEST(SoilSequence, ShortSoilRunRendersThroughMakeWithTheCameraFixed) {
  const fs::path d = test_dir("soil_sequence");
  const std::string cmd =
      "make -C " DRIFT_SOURCE_DIR "/data/scenes soil_sequence OUT=" + d.string() +
      " DRIFT=" DRIFT_EXECUTABLE +
      " SOIL_SEQ_FRAMES='00020 00040' SOIL_SEQ_RUN='--steps 40 --frame-every 20'"
      " SOIL_SEQ='--size 64x40 --spp 1 --exposure 0' THREADS=2 > " +
      (d / "make.txt").string() + " 2>&1";
  const int raw = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << slurp(d / "make.txt");
  const fs::path seq = d / "soil_sequence";
  for (const char* f : {"frame_00020", "frame_00040"}) {
    EXPECT_TRUE(fs::exists(seq / (std::string(f) + ".png"))) << f;
    EXPECT_TRUE(fs::exists(seq / "frames" / (std::string(f) + ".ply"))) << f;
  }
  EXPECT_TRUE(fs::exists(d / "soil_sequence.png"));
  const std::vector<double> first = numbers(camera_of(slurp(seq / "frame_00020.json"))),
                            last = numbers(camera_of(slurp(seq / "frame_00040.json")));
  ASSERT_EQ(first.size(), 3u + 9u + 16u);
  ASSERT_EQ(first.size(), last.size());
  for (std::size_t i = 0; i < first.size(); ++i) EXPECT_NEAR(first[i], last[i], 1e-6) << i;
  // The column slumped between the frames: its top and flanks moved in the view.
  const drift::render::Image a = drift::render::read_image(seq / "frame_00020.png"),
                             b = drift::render::read_image(seq / "frame_00040.png");
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  std::size_t changed = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    changed += std::abs(a.pixels[i] - b.pixels[i]) > 0.05f;
  EXPECT_GT(changed, a.pixels.size() / 50) << changed << " of " << a.pixels.size() << " values";
}
