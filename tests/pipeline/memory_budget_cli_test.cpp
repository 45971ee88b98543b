// drift render --memory-budget (issue 36 item 2, render/paged_terrain.h) from
// the command line: the same PNG at a budget of about one page and of all of
// them, the cache's line printed, and bad budgets refused (not a size: exit
// 2; below one page: exit 1 naming the DEM) with nothing written.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "render/image_io.h"
#include "terrain/raster_io.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;

namespace {

using drift::testing::put;
using drift::testing::slurp;

struct Result {
  int status;
  std::string log;
};

Result run_drift(const std::string& args, const fs::path& d) {
  const fs::path log = d / "log.txt";
  const std::string cmd =
      std::string("timeout 300 ") + DRIFT_EXECUTABLE + " " + args + " > " + log.string() + " 2>&1";
  const int raw = std::system(cmd.c_str());
  return {WEXITSTATUS(raw), slurp(log)};
}

// Relief of 600 x 520 cells (a tiled GeoTIFF) and a scene without the
// surround ring, which the out-of-core terrain does not build.
fs::path scene(const fs::path& d) {
  drift::terrain::HeightField g(600, 520, 0.0f, drift::terrain::local_georeference(5.0));
  for (int r = 0; r < g.height(); ++r)
    for (int c = 0; c < g.width(); ++c)
      g(c, r) = static_cast<float>(300.0 + 80.0 * std::sin(c * 0.02) * std::cos(r * 0.03) +
                                   20.0 * std::fabs(std::sin(c * 0.11 + r * 0.07)));
  drift::terrain::write_geotiff(g, d / "dem.tif");
  const fs::path s = d / "scene.toml";
  put(s,
      "[terrain]\nraster = \"dem.tif\"\nsurround_reach = 0\n[sun]\nazimuth = 135\n"
      "elevation = 30\n[render]\nspp = 1\n");
  return s;
}

}  // namespace

TEST(MemoryBudgetCli, TheSamePngAtAnyBudget) {
  const fs::path d = drift::testing::test_dir("drift_memory_budget_same");
  const std::string s = scene(d).string();
  const std::string frame = " --size 40x24 --exposure 0 -o ";
  const Result small =
      run_drift("render " + s + frame + (d / "small.png").string() + " --memory-budget 400K", d);
  ASSERT_EQ(small.status, 0) << small.log;
  EXPECT_NE(small.log.find("terrain cache: "), std::string::npos) << small.log;
  EXPECT_NE(small.log.find("of a 400.0 KiB budget"), std::string::npos) << small.log;
  const Result large =
      run_drift("render " + s + frame + (d / "large.png").string() + " --memory-budget 64M", d);
  ASSERT_EQ(large.status, 0) << large.log;
  EXPECT_EQ(slurp(d / "small.png"), slurp(d / "large.png"));
}

TEST(MemoryBudgetCli, RefusesABadBudgetAndWritesNothing) {
  const fs::path d = drift::testing::test_dir("drift_memory_budget_bad");
  const std::string s = scene(d).string();
  const std::string out = " --size 40x24 -o " + (d / "out.png").string();
  const Result not_a_size = run_drift("render " + s + out + " --memory-budget 4X", d);
  EXPECT_EQ(not_a_size.status, 2) << not_a_size.log;
  EXPECT_NE(not_a_size.log.find("--memory-budget '4X' is not a size"), std::string::npos)
      << not_a_size.log;
  const Result too_small = run_drift("render " + s + out + " --memory-budget 100K", d);
  EXPECT_EQ(too_small.status, 1) << too_small.log;
  EXPECT_NE(too_small.log.find("dem.tif"), std::string::npos) << too_small.log;
  EXPECT_NE(too_small.log.find("cannot hold one block"), std::string::npos) << too_small.log;
  EXPECT_FALSE(fs::exists(d / "out.png"));
}

// --height-bits 16 (issue 36 item 1): the DEM held in core as 16-bit heights
// renders a PNG close to the float one (a mean linear difference under 0.2 %
// of full scale); an unknown width and the pairing with --memory-budget (the
// pages hold floats) are usage errors (exit 2) that write nothing.
TEST(MemoryBudgetCli, SixteenBitHeightsRenderCloseToFloatsAndBadUsesAreRefused) {
  const fs::path d = drift::testing::test_dir("drift_height_bits");
  const std::string s = scene(d).string();
  const std::string frame = " --size 40x24 --exposure 0 -o ";
  const Result floats = run_drift("render " + s + frame + (d / "float.png").string(), d);
  ASSERT_EQ(floats.status, 0) << floats.log;
  const Result sixteen =
      run_drift("render " + s + frame + (d / "16.png").string() + " --height-bits 16", d);
  ASSERT_EQ(sixteen.status, 0) << sixteen.log;
  const drift::render::Image pa = drift::render::read_image(d / "float.png");
  const drift::render::Image pb = drift::render::read_image(d / "16.png");
  ASSERT_EQ(pa.pixels.size(), pb.pixels.size());
  ASSERT_FALSE(pa.pixels.empty());
  double diff = 0.0;
  for (std::size_t i = 0; i < pa.pixels.size(); ++i) diff += std::fabs(pa.pixels[i] - pb.pixels[i]);
  // read_image gives linear values in [0, 1] (from sRGB).
  EXPECT_LT(diff / static_cast<double>(pa.pixels.size()), 2e-3);
  const Result eight =
      run_drift("render " + s + frame + (d / "out.png").string() + " --height-bits 8", d);
  EXPECT_EQ(eight.status, 2) << eight.log;
  const Result paged = run_drift(
      "render " + s + frame + (d / "out.png").string() + " --height-bits 16 --memory-budget 64M",
      d);
  EXPECT_EQ(paged.status, 2) << paged.log;
  EXPECT_NE(paged.log.find("--height-bits 16"), std::string::npos) << paged.log;
  EXPECT_FALSE(fs::exists(d / "out.png"));
}
