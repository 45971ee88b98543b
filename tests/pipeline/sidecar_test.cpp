// drift render --sidecar: the frame's ground truth as JSON (docs/rendering.md,
// "Ground truth sidecar"). The test projects the EXR's P with the sidecar's
// pose and intrinsics alone and must land on the pixel P came from.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "render/cryptomatte.h"
#include "render/image_io.h"
#include "terrain/raster_io.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using drift::testing::drift_log;
using drift::testing::put;
using drift::testing::run_drift;
using drift::testing::slurp;
using drift::testing::test_dir;

namespace {

// The numbers after "key": in `json`, in order (a flat read of its value).
std::vector<double> numbers_after(const std::string& json, const std::string& key, int count) {
  const auto at = json.find("\"" + key + "\":");
  EXPECT_NE(at, std::string::npos) << key;
  std::vector<double> out;
  const std::regex number(R"([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)");
  const std::string rest = json.substr(at + key.size() + 3);
  for (auto it = std::sregex_iterator(rest.begin(), rest.end(), number);
       it != std::sregex_iterator() && static_cast<int>(out.size()) < count; ++it)
    out.push_back(std::stod(it->str()));
  return out;
}

}  // namespace

TEST(Sidecar, PoseAndIntrinsicsProjectPBackOntoItsPixel) {
  const fs::path d = test_dir("sidecar");
  drift::terrain::GeoReference geo = drift::terrain::local_georeference(10.0);
  geo.geotransform[0] = 600000.0;
  geo.geotransform[3] = 4000000.0;
  drift::terrain::HeightField dem(48, 48, 0.0f, geo);
  for (int r = 0; r < 48; ++r)
    for (int c = 0; c < 48; ++c)
      dem(c, r) = static_cast<float>(900.0 + 30.0 * std::sin(c / 6.0) * std::cos(r / 8.0));
  drift::terrain::write_geotiff(dem, d / "dem.tif");
  put(d / "scene.toml",
      "[terrain]\nraster = \"dem.tif\"\nmaterial = \"rock\"\n[render]\nspp = 4\n");
  ASSERT_EQ(run_drift("render " + (d / "scene.toml").string() +
                          " --size 40x30 --from 600050,3999650,1100 --to 600300,3999800,900 "
                          "--sidecar -o " +
                          (d / "f.exr").string(),
                      d),
            0)
      << drift_log(d);
  const std::string json = slurp(d / "f.json");
  ASSERT_FALSE(json.empty()) << "--sidecar writes f.json beside f.exr";
  EXPECT_EQ(numbers_after(json, "width", 1)[0], 40);
  EXPECT_EQ(numbers_after(json, "height", 1)[0], 30);
  const double fx = numbers_after(json, "fx", 1)[0], fy = numbers_after(json, "fy", 1)[0];
  const double cx = numbers_after(json, "cx", 1)[0], cy = numbers_after(json, "cy", 1)[0];
  const std::vector<double> m = numbers_after(json, "world_to_camera", 16);
  const std::vector<double> origin = numbers_after(json, "origin", 3);
  const std::vector<double> position = numbers_after(json, "position", 3);
  EXPECT_NEAR(position[0], 600050.0, 1e-3);
  EXPECT_NEAR(position[2], 1100.0, 1e-3);
  // The class and object IDs are the mattes'.
  EXPECT_NE(json.find("\"rock\": {\"id_hex\": \"" +
                      drift::render::cryptomatte_hex(drift::render::cryptomatte_id("rock"))),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"terrain\": {\"id_hex\""), std::string::npos);
  const auto exr = drift::render::read_image(d / "f.exr");
  const int px = exr.channel_index("P.X"), sky = exr.channel_index("mask.sky");
  double worst = 0.0;
  int checked = 0;
  for (int y = 0; y < exr.height; ++y) {
    for (int x = 0; x < exr.width; ++x) {
      if (exr.at(x, y, sky) > 0.0f) continue;
      double p[3], cam[3];
      for (int i = 0; i < 3; ++i) p[i] = exr.at(x, y, px + i) + origin[static_cast<std::size_t>(i)];
      for (int r = 0; r < 3; ++r)
        cam[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
      // OpenCV: pixel centres on integers.
      const double u = fx * cam[0] / cam[2] + cx, v = fy * cam[1] / cam[2] + cy;
      worst = std::max({worst, std::abs(u - x), std::abs(v - y)});
      ++checked;
    }
  }
  EXPECT_GT(checked, 600);
  EXPECT_LT(worst, 0.3) << "pixels between P projected by the sidecar and its pixel";
  std::printf("sidecar: P of %d pixels projects within %.3f px of its pixel\n", checked, worst);
}
