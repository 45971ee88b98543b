// The out-of-core terrain (render/paged_terrain.h, issue 36 item 2): a tiled
// GeoTIFF made here, traced from pages through an LRU cache, gives the same
// hits and the same image bits as the DEM held in core, at a budget of one
// page (pages dropped and read again all the time) or of all of them, on one
// thread or two.
#include "render/paged_terrain.h"

#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "render/camera_setup.h"
#include "render/renderer.h"
#include "render/terrain_scene.h"
#include "terrain/error.h"
#include "terrain/raster_io.h"

using namespace drift::render;
namespace fs = std::filesystem;

namespace {

constexpr int kWidth = 300, kHeight = 220;  // vertices: pages of 32 cells leave ragged edges
constexpr int kPage = 32;
constexpr float kNodata = -9999.0f;

// Relief with ridges, a pit and a patch of nodata, as a tiled (64 x 64),
// DEFLATE-compressed GeoTIFF with overviews, at UTM-sized coordinates.
fs::path tiled_dem() {
  drift::terrain::ensure_gdal();
  // One file a test: ctest runs tests side by side.
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path path =
      fs::temp_directory_path() / (std::string("drift_paged_") + info->name() + ".tif");
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  const char* options[] = {"TILED=YES", "BLOCKXSIZE=64", "BLOCKYSIZE=64", "COMPRESS=DEFLATE",
                           nullptr};
  GDALDataset* ds =
      driver->Create(path.c_str(), kWidth, kHeight, 1, GDT_Float32, const_cast<char**>(options));
  double gt[6] = {600000.0, 2.0, 0.0, 4000000.0, 0.0, -2.0};
  ds->SetGeoTransform(gt);
  GDALRasterBand* band = ds->GetRasterBand(1);
  band->SetNoDataValue(kNodata);
  std::vector<float> z(static_cast<std::size_t>(kWidth) * kHeight);
  for (int r = 0; r < kHeight; ++r)
    for (int c = 0; c < kWidth; ++c) {
      float h = static_cast<float>(
          900.0 + 60.0 * std::sin(c * 0.05) * std::cos(r * 0.07) +
          25.0 * std::fabs(std::sin(c * 0.13 + r * 0.11)) -
          40.0 * std::exp(-((c - 200) * (c - 200) + (r - 60) * (r - 60)) / 300.0));
      if (c >= 40 && c < 47 && r >= 150 && r < 158) h = kNodata;
      z[static_cast<std::size_t>(r) * kWidth + c] = h;
    }
  EXPECT_EQ(band->RasterIO(GF_Write, 0, 0, kWidth, kHeight, z.data(), kWidth, kHeight, GDT_Float32,
                           0, 0, nullptr),
            CE_None);
  int levels[] = {2, 4};
  EXPECT_EQ(ds->BuildOverviews("AVERAGE", 2, levels, 0, nullptr, nullptr, nullptr), CE_None);
  GDALClose(GDALDataset::ToHandle(ds));
  return path;
}

SceneInput bare_input() {
  SceneInput in;
  in.sun.elevation_deg = 25.0;
  in.surround.reach = 0.0;  // the paged scene has no surround ring
  return in;
}

Image render(const TerrainScene& scene, const SceneInput& in, const Camera& camera, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  RenderSettings rs;
  rs.width = 48;
  rs.height = 32;
  rs.samples_per_pixel = 2;
  return render_image(scene, in, camera, rs);
}

}  // namespace

TEST(PagedTerrain, TracesTheSameHitsAsTheDemInCore) {
  const fs::path dem = tiled_dem();
  SceneInput in = bare_input();
  in.terrain = drift::terrain::read_raster(dem);
  const TerrainScene core(in, TerrainGeometry::HeightField);
  PagedTerrain paged(dem, 4 * (kPage + 1) * (kPage + 1) * sizeof(float), 1.0f, kPage);
  const TerrainScene out(bare_input(), paged);
  EXPECT_EQ(out.origin(), core.origin());
  EXPECT_EQ(out.highest_point(), core.highest_point());
  EXPECT_EQ(out.lowest_point(), core.lowest_point());
  EXPECT_EQ(out.bottom(), core.bottom());
  EXPECT_EQ(out.top(), core.top());
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int hits = 0;
  for (int i = 0; i < 4000; ++i) {
    // From above the relief towards anywhere below, grazing rays included.
    const Eigen::Vector3f o(300.0f * u(rng), 220.0f * u(rng), 120.0f + 60.0f * u(rng));
    const Eigen::Vector3f d =
        Eigen::Vector3f(u(rng), u(rng), -0.05f - 0.5f * std::fabs(u(rng))).normalized();
    Eigen::Vector3f n_core, n_out;
    const float t_core = core.hit_distance(o, d, &n_core);
    const float t_out = out.hit_distance(o, d, &n_out);
    ASSERT_EQ(t_core, t_out) << "ray " << i;
    if (std::isfinite(t_core)) {
      ++hits;
      ASSERT_EQ(n_core, n_out) << "ray " << i;
      const Eigen::Vector3f p = o + t_core * d;
      ASSERT_EQ(core.height_at(p.x(), p.y()), out.height_at(p.x(), p.y())) << "ray " << i;
    }
  }
  EXPECT_GT(hits, 2000);
  const BlockCacheStats s = paged.cache_stats();
  EXPECT_LE(s.peak_resident, paged.budget());
  EXPECT_GT(s.misses, 70u);  // 10 x 7 pages, most read more than once
  EXPECT_GT(s.hits, 0u);
}

TEST(PagedTerrain, ImagesAreTheSameBitsAtAnyBudgetAndThreadCount) {
  const fs::path dem = tiled_dem();
  SceneInput in = bare_input();
  in.terrain = drift::terrain::read_raster(dem);
  const TerrainScene core(in, TerrainGeometry::HeightField);
  const Camera camera = default_camera(core);
  const Image reference = render(core, in, camera, 2);

  const std::uint64_t one_page = (kPage + 1) * (kPage + 1) * sizeof(float);
  for (const std::uint64_t budget : {one_page, std::uint64_t{1} << 20}) {
    for (const int threads : {1, 2}) {
      PagedTerrain paged(dem, budget, 1.0f, kPage);
      const SceneInput bare = bare_input();
      const TerrainScene scene(bare, paged);
      const Image image = render(scene, bare, camera, threads);
      ASSERT_EQ(image.pixels.size(), reference.pixels.size());
      EXPECT_TRUE(image.pixels == reference.pixels)
          << "budget " << budget << " B, " << threads << " thread(s)";
      const BlockCacheStats s = paged.cache_stats();
      EXPECT_LE(s.peak_resident, budget);
      if (budget == one_page)
        EXPECT_GT(s.misses, 70u);  // pages read again and again
      else
        EXPECT_LE(s.misses, 70u);  // each page read once at most
    }
  }
}

// The opening scan reads strips of page_cells() rows side by side, each leaf
// row whose last vertex row opens the next strip completed from that strip
// (issue 36: the parallel opening read). Whatever the strips (16, 32 or one
// for the whole raster) and the threads, the leaves and extremes are the same
// bits.
TEST(PagedTerrain, ScanGivesTheSameLeavesAtAnyStripAndThreadCount) {
  const fs::path dem = tiled_dem();
  std::vector<HeightFieldBlocks::MinMax> reference;
  Eigen::Vector3f highest, lowest;
  for (const int page : {256, 16, 32}) {
    for (const int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      PagedTerrain paged(dem, std::uint64_t{1} << 20, 1.0f, page);
      const std::vector<HeightFieldBlocks::MinMax> leaves = paged.take_leaves();
      ASSERT_EQ(leaves.size(), std::size_t{75} * 55);  // 299 x 219 cells in leaves of 4
      if (reference.empty()) {
        reference = leaves;
        highest = paged.highest(), lowest = paged.lowest();
        continue;
      }
      for (std::size_t i = 0; i < leaves.size(); ++i) {
        ASSERT_EQ(leaves[i].lo, reference[i].lo) << "leaf " << i << ", strips of " << page;
        ASSERT_EQ(leaves[i].hi, reference[i].hi) << "leaf " << i << ", strips of " << page;
      }
      EXPECT_EQ(paged.highest(), highest) << "strips of " << page << ", " << threads;
      EXPECT_EQ(paged.lowest(), lowest) << "strips of " << page << ", " << threads;
      EXPECT_EQ(paged.scan_bytes(), std::uint64_t{kWidth} * kHeight * sizeof(float));
    }
  }
}

TEST(PagedTerrain, RefusesABudgetBelowOnePage) {
  const fs::path dem = tiled_dem();
  try {
    PagedTerrain paged(dem, 1000, 1.0f, kPage);
    FAIL() << "a budget of 1000 B was taken for pages of 4356 B";
  } catch (const drift::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cannot hold one block"), std::string::npos) << what;
    EXPECT_NE(what.find(dem.string()), std::string::npos) << what;  // which DEM
    EXPECT_NE(what.find("4356 B"), std::string::npos) << what;      // a page's size
  }
}

TEST(PagedTerrain, NamesAMissingRaster) {
  try {
    PagedTerrain paged(fs::temp_directory_path() / "drift_no_such_dem.vrt", 1 << 20, 1.0f);
    FAIL();
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("drift_no_such_dem.vrt"), std::string::npos) << e.what();
  }
}
