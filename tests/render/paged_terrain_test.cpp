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

// The budget of `pages` pages beside what the terrain holds in memory.
std::uint64_t pages_budget(const fs::path& dem, std::uint64_t pages) {
  const PagedTerrain probe(dem, std::uint64_t{1} << 30, 1.0f, kPage);
  return probe.held_bytes() + pages * probe.page_bytes();
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
  PagedTerrain paged(dem, pages_budget(dem, 4), 1.0f, kPage);
  const TerrainScene out(bare_input(), paged);
  EXPECT_EQ(out.origin(), core.origin());
  EXPECT_EQ(out.highest_point(), core.highest_point());
  EXPECT_EQ(out.lowest_point(), core.lowest_point());
  // Embree's boxes, padded by a millionth of their coordinates, are groups
  // of blocks out of core: the scene's bounds differ by that padding.
  EXPECT_NEAR(out.bottom(), core.bottom(), 1e-3f);
  EXPECT_NEAR(out.top(), core.top(), 1e-3f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int hits = 0, ties = 0;
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
      // Out of core Embree's primitives are groups of 4 x 4 blocks, tried
      // nearest first: on a tie (a hit on an edge two blocks share, the same
      // distance) the other block's triangle may be reported.
      ties += !(n_core == n_out);
      const Eigen::Vector3f p = o + t_core * d;
      ASSERT_EQ(core.height_at(p.x(), p.y()), out.height_at(p.x(), p.y())) << "ray " << i;
    }
  }
  EXPECT_GT(hits, 2000);
  EXPECT_LE(ties, hits / 200);
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

  const std::uint64_t one_page = pages_budget(dem, 1);
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
      EXPECT_LE(s.peak_resident + paged.held_bytes(), budget);
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
  std::vector<float> coarse;
  for (const int page : {256, 16, 32}) {
    for (const int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      PagedTerrain paged(dem, std::uint64_t{1} << 20, 1.0f, page);
      const std::vector<HeightFieldBlocks::MinMax> leaves = paged.take_block_bounds();
      ASSERT_EQ(leaves.size(), std::size_t{19} * 14);  // 299 x 219 cells in blocks of 16
      const std::vector<float> samples = paged.take_coarse();
      ASSERT_EQ(samples.size(), std::size_t{39} * 29);  // every 8th vertex and the last
      if (reference.empty()) {
        reference = leaves;
        coarse = samples;
        highest = paged.highest(), lowest = paged.lowest();
        continue;
      }
      for (std::size_t i = 0; i < leaves.size(); ++i) {
        ASSERT_EQ(leaves[i].lo, reference[i].lo) << "leaf " << i << ", strips of " << page;
        ASSERT_EQ(leaves[i].hi, reference[i].hi) << "leaf " << i << ", strips of " << page;
      }
      EXPECT_TRUE(samples == coarse) << "strips of " << page << ", " << threads;
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
    FAIL() << "a budget of 1000 B was taken for pages of 4996 B";
  } catch (const drift::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cannot hold one block"), std::string::npos) << what;
    EXPECT_NE(what.find(dem.string()), std::string::npos) << what;  // which DEM
    EXPECT_NE(what.find("4996 B"), std::string::npos)
        << what;  // a page's size: 33^2 heights, 80 nodes
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

// ---------------------------------------------------------------------------
// Level of detail by footprint (issue 36 item 2; render/height_field.h,
// LodView): distant vertices slide onto the surfaces through every 8th and
// 16th vertex, continuously with the camera, the same whatever the cache.

namespace {

// A camera low over the DEM's south edge looking north across it, so the
// frame runs from full resolution to level 4; `bias` makes levels coarser.
struct LodCase {
  Camera camera;
  LodView view;
};
LodCase lod_case(const TerrainScene& scene, int width, float bias) {
  LodCase k;
  const Eigen::Vector3d o = scene.origin();
  k.camera.from = o + Eigen::Vector3d(0.0, -250.0, 120.0);
  k.camera.to = o + Eigen::Vector3d(0.0, 200.0, 0.0);
  k.camera.vertical_fov_deg = 40.0;
  const CameraRays rays = make_camera_rays(scene, k.camera, width, width * 2 / 3);
  k.view = {rays.eye, rays.footprint_spread(), bias};
  return k;
}

double mean_abs_difference(const Image& a, const Image& b) {
  double sum = 0, ref = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    sum += std::fabs(static_cast<double>(a.pixels[i]) - b.pixels[i]);
    ref += std::fabs(static_cast<double>(b.pixels[i]));
  }
  return sum / ref;
}

}  // namespace

// With LOD the frame stays within 5 % (mean absolute difference over the mean)
// of full resolution, its depths within 0.5 % on 95 % of the pixels, and it
// reads fewer pages.
TEST(LevelOfDetail, RenderIsCloseToFullResolutionAndReadsFewerPages) {
  const fs::path dem = tiled_dem();
  // A budget that holds every page, so misses count the distinct pages each
  // frame reads: with one page the two threads' order decides how often a
  // page is read again, and the counts crossed from run to run.
  const std::uint64_t budget = pages_budget(dem, std::uint64_t{1} << 16);
  const SceneInput in = bare_input();
  PagedTerrain full_paged(dem, budget, 1.0f, kPage);
  const TerrainScene full(in, full_paged);
  PagedTerrain lod_paged(dem, budget, 1.0f, kPage);
  TerrainScene lod(in, lod_paged);
  const LodCase k = lod_case(lod, 48, 0.0f);
  lod.set_lod(k.view);
  const Image a = render(full, in, k.camera, 2);
  const Image b = render(lod, in, k.camera, 2);
  const double d = mean_abs_difference(b, a);
  EXPECT_LT(d, 0.05);
  EXPECT_GT(d, 0.0);  // the LOD is on
  // Depths of the frame's pixel centres.
  const CameraRays rays = make_camera_rays(full, k.camera, 96, 64);
  int close = 0, hits = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 96; ++x) {
      const Eigen::Vector3f dir = rays.direction(x + 0.5f, y + 0.5f);
      const float ta = full.hit_distance(rays.eye, dir), tb = lod.hit_distance(rays.eye, dir);
      if (!std::isfinite(ta)) continue;
      ++hits;
      close += std::isfinite(tb) && std::fabs(tb - ta) <= 0.005f * ta;
    }
  EXPECT_GT(hits, 3000);
  EXPECT_GE(close, hits * 95 / 100) << close << " of " << hits;
  EXPECT_LT(lod_paged.cache_stats().misses, full_paged.cache_stats().misses);
}

// The level depends on the view alone: the same bits at a budget of one page
// or of all of them, on one thread or two.
TEST(LevelOfDetail, ImagesAreTheSameBitsAtAnyBudgetAndThreadCount) {
  const fs::path dem = tiled_dem();
  Image reference;
  for (const std::uint64_t pages : {1, 100}) {
    for (const int threads : {1, 2}) {
      PagedTerrain paged(dem, pages_budget(dem, pages), 1.0f, kPage);
      const SceneInput in = bare_input();
      TerrainScene scene(in, paged);
      const LodCase k = lod_case(scene, 48, 1.0f);
      scene.set_lod(k.view);
      const Image image = render(scene, in, k.camera, threads);
      if (reference.pixels.empty()) {
        reference = image;
        continue;
      }
      EXPECT_TRUE(image.pixels == reference.pixels)
          << pages << " page(s), " << threads << " thread(s)";
    }
  }
}

// A step of the camera moves every vertex's height by at most the level's
// change times the height between the levels there (the morph): nothing pops.
// The step changes any vertex's level by at most 0.01, so no vertex may move
// by more than 2 % of the largest difference between adjacent levels.
TEST(LevelOfDetail, ACameraStepMovesNoVertexByAJump) {
  const fs::path dem = tiled_dem();
  SceneInput in = bare_input();
  in.terrain = drift::terrain::read_raster(dem);
  const TerrainScene probe(in, TerrainGeometry::HeightField);
  const LodCase k = lod_case(probe, 48, 1.0f);
  HeightGrid grid;
  grid.width = kWidth, grid.height = kHeight, grid.dx = 2.0f, grid.dy = 2.0f;
  grid.z.resize(static_cast<std::size_t>(kWidth) * kHeight);
  for (int r = 0; r < kHeight; ++r)
    for (int c = 0; c < kWidth; ++c) {
      const float v = in.terrain(c, r);
      grid.z[static_cast<std::size_t>(r) * kWidth + c] = std::isnan(v) ? 860.0f : v;
    }
  grid.x0 = -299.0f, grid.y0 = 219.0f;
  HeightFieldBlocks a(grid), b(grid);
  // The nearest vertex is ~100 m away: a 0.5 m step changes levels by < 0.01.
  const Eigen::Vector3f eye(0.0f, -320.0f, 1000.0f);
  LodView va{eye, k.view.spread, 1.0f}, vb = va;
  vb.eye += Eigen::Vector3f(0.3f, 0.4f, 0.0f);
  a.set_lod(va);
  b.set_lod(vb);
  HeightFieldBlocks off(grid);
  float largest_jump = 0.0f, largest_move = 0.0f;
  int moved = 0;
  for (int r = 0; r < kHeight; ++r)
    for (int c = 0; c < kWidth; ++c) {
      largest_jump = std::max(largest_jump, std::fabs(a.height(c, r) - off.height(c, r)));
      const float m = std::fabs(a.height(c, r) - b.height(c, r));
      largest_move = std::max(largest_move, m);
      moved += m > 0.0f;
    }
  EXPECT_GT(largest_jump, 1.0f);  // the levels differ by metres here
  EXPECT_GT(moved, 1000);         // and the step does move vertices
  EXPECT_LE(largest_move, 0.02f * largest_jump) << largest_move << " of " << largest_jump;
}

// Where a full-resolution block meets one at a coarser level (and levels
// meet each other) the surface has no crack: rays aimed at points on every
// block edge, against the surface, all stop there (within the rounding).
TEST(LevelOfDetail, RaysAimedAtLevelSeamsAllHit) {
  const fs::path dem = tiled_dem();
  SceneInput in = bare_input();
  in.terrain = drift::terrain::read_raster(dem);
  TerrainScene scene(in, TerrainGeometry::HeightField);
  LodView view = lod_case(scene, 48, 0.0f).view;
  view.spread *= 4.0f;  // levels 0 to 4 all within the DEM
  scene.set_lod(view);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float x0 = -299.0f, y0 = 219.0f, cell = 2.0f;
  constexpr int kB = HeightFieldBlocks::kBlock;
  int rays = 0, passed = 0;
  for (int edge = kB; edge < kWidth - 1; edge += kB)
    for (int s = 0; s < 200; ++s) {
      for (const bool vertical : {true, false}) {
        if (!vertical && edge >= kHeight - 1) continue;
        const float along = u(rng) * (vertical ? kHeight - 1 : kWidth - 1) * cell;
        const float x = vertical ? x0 + edge * cell : x0 + along;
        const float y = vertical ? y0 - along : y0 - edge * cell;
        const Eigen::Vector3f target(x, y, scene.height_at(x, y));
        // Against the surface's normal, tilted up to ~20 degrees: never
        // grazing, so a target rounded a hair above the surface is met
        // within millimetres of it.
        const Eigen::Vector3f n = scene.smooth_normal(x, y);
        const Eigen::Vector3f dir =
            -(n + 0.35f * Eigen::Vector3f(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f))
                 .normalized();
        const Eigen::Vector3f o = target - 400.0f * dir;
        const float t = scene.hit_distance(o, dir);
        ++rays;
        if (!(t <= 400.0f + 0.01f)) ++passed;
      }
    }
  EXPECT_GT(rays, 5000);
  EXPECT_EQ(passed, 0) << passed << " of " << rays << " rays passed a seam";
}
