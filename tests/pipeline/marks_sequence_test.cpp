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

// Runs `make -C data/scenes TARGET` into a fresh OUT with `vars`, then checks
// the two frames `first` and `last` (names frame_NNNNN) of OUT/TARGET: each
// image, its product in frames/ (`product` extension) and the sheet exist;
// the sidecars' camera (pose and world_to_camera) agree within 1e-6 (a camera
// that moved by a millimetre, or re-aimed by a microradian, fails); and more
// than 1 / `changed_share` of the image values changed by over 0.05.
void expect_fixed_camera_sequence(const std::string& target, const std::string& vars,
                                  const std::string& first, const std::string& last,
                                  const std::string& product, std::size_t changed_share) {
  const fs::path d = test_dir(target);
  const std::string cmd = "make -C " DRIFT_SOURCE_DIR "/data/scenes " + target +
                          " OUT=" + d.string() + " DRIFT=" DRIFT_EXECUTABLE " " + vars +
                          " THREADS=2 > " + (d / "make.txt").string() + " 2>&1";
  const int raw = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << slurp(d / "make.txt");
  const fs::path seq = d / target;
  for (const std::string& f : {first, last}) {
    EXPECT_TRUE(fs::exists(seq / (f + ".png"))) << f;
    EXPECT_TRUE(fs::exists(seq / "frames" / (f + product))) << f;
  }
  EXPECT_TRUE(fs::exists(d / (target + ".png")));
  const std::vector<double> a_cam = numbers(camera_of(slurp(seq / (first + ".json")))),
                            b_cam = numbers(camera_of(slurp(seq / (last + ".json"))));
  ASSERT_EQ(a_cam.size(), 3u + 9u + 16u);
  ASSERT_EQ(a_cam.size(), b_cam.size());
  for (std::size_t i = 0; i < a_cam.size(); ++i) EXPECT_NEAR(a_cam[i], b_cam[i], 1e-6) << i;
  const drift::render::Image a = drift::render::read_image(seq / (first + ".png")),
                             b = drift::render::read_image(seq / (last + ".png"));
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  std::size_t changed = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    changed += std::abs(a.pixels[i] - b.pixels[i]) > 0.05f;
  EXPECT_GT(changed, a.pixels.size() / changed_share)
      << changed << " of " << a.pixels.size() << " values";
}

}  // namespace

// The eye is kept in float relative to the scene's origin, which follows the
// ground: 3e-8 m apart here. The ball's trough covers a good part of the view.
TEST(MarksSequence, ShortSequenceRendersThroughMakeWithTheCameraFixed) {
  expect_fixed_camera_sequence("marks_sequence",
                               "SEQ_FRAMES='00000 00030' SEQ='--size 64x40 --spp 1 --exposure 1.1'",
                               "frame_00000", "frame_00030", ".tif", 20);
}

// `make -C data/scenes soil_sequence`: a soil run's frames (drift soil
// --frames, a surface mesh every 20 steps) each rendered as the scene's
// object under the fixed camera of soil_sequence.toml. Short: 40 steps, 2
// frames at 64x40, 1 spp. The column slumped between them.
TEST(SoilSequence, ShortSoilRunRendersThroughMakeWithTheCameraFixed) {
  expect_fixed_camera_sequence("soil_sequence",
                               "SOIL_SEQ_FRAMES='00020 00040' SOIL_SEQ_RUN='--steps 40 "
                               "--frame-every 20' SOIL_SEQ='--size 64x40 --spp 1 --exposure 0'",
                               "frame_00020", "frame_00040", ".ply", 50);
}
