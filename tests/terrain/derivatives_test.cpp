// Slope, aspect and normals: analytic planes, and agreement with `gdaldem`
// (GDAL's own DEM processing, Horn's method) on a real DEM.
#include "terrain/derivatives.h"

#include <gdal_priv.h>
#include <gdal_utils.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "terrain/raster_io.h"

namespace fs = std::filesystem;
using namespace drift::terrain;

namespace {

// z = a*east + b*north on a north-up grid of `cell` metres.
HeightField plane(int w, int h, double cell, float a, float b) {
  HeightField g(w, h, 0.0f, local_georeference(cell));
  for (int row = 0; row < h; ++row) {
    for (int x = 0; x < w; ++x) {
      const auto c = g.geo().cell_center(x, row);
      g(x, row) = static_cast<float>(a * c[0] + b * c[1] + 1000.0);
    }
  }
  return g;
}

// Runs `gdaldem MODE -compute_edges` on `source` and returns the result.
HeightField gdaldem(const fs::path& source, const char* mode, const fs::path& out) {
  ensure_gdal();
  GDALDatasetH src = GDALOpen(source.c_str(), GA_ReadOnly);
  EXPECT_NE(src, nullptr);
  char* argv[] = {const_cast<char*>("-compute_edges"), nullptr};
  GDALDEMProcessingOptions* options = GDALDEMProcessingOptionsNew(argv, nullptr);
  int usage_error = 0;
  GDALDatasetH dst = GDALDEMProcessing(out.c_str(), src, mode, nullptr, options, &usage_error);
  EXPECT_NE(dst, nullptr);
  GDALDEMProcessingOptionsFree(options);
  GDALClose(dst);
  GDALClose(src);
  return read_raster(out);
}

fs::path temp_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto dir = fs::temp_directory_path() /
             (std::string("drift_derivs_") + info->test_suite_name() + "_" + info->name());
  fs::create_directories(dir);
  return dir;
}

}  // namespace

TEST(Derivatives, PlaneHasExactSlopeAspectAndNormal) {
  // Rises 0.5 m per metre east and 0.25 north: it faces (downhill) west-south-west.
  const HeightField dem = plane(9, 7, 10.0, 0.5f, 0.25f);
  const auto slope = slope_degrees(dem);
  const auto aspect = aspect_degrees(dem);
  const auto n = normals(dem);
  const double expected_slope = std::atan(std::hypot(0.5, 0.25)) * 180.0 / std::numbers::pi;
  const double expected_aspect = 180.0 + std::atan2(0.5, 0.25) * 180.0 / std::numbers::pi;
  // Interior cells only: at the border the centre's height stands in for the
  // missing neighbours, which halves the difference there (as in gdaldem).
  for (int row = 1; row < 6; ++row) {
    for (int x = 1; x < 8; ++x) {
      EXPECT_NEAR(slope(x, row), expected_slope, 1e-4);
      EXPECT_NEAR(aspect(x, row), expected_aspect, 1e-3);
      const Eigen::Vector3f expected = Eigen::Vector3f(-0.5f, -0.25f, 1.0f).normalized();
      EXPECT_NEAR((n(x, row) - expected).norm(), 0.0f, 1e-6f);
    }
  }
}

TEST(Derivatives, AspectNamesTheCompassDirectionDownhill) {
  const auto at_centre = [](float a, float b) {
    return aspect_degrees(plane(5, 5, 1.0, a, b))(2, 2);
  };
  EXPECT_NEAR(at_centre(0.0f, 1.0f), 180.0f, 1e-4);  // rises north: faces south
  EXPECT_NEAR(at_centre(0.0f, -1.0f), 0.0f, 1e-4);   // rises south: faces north
  EXPECT_NEAR(at_centre(1.0f, 0.0f), 270.0f, 1e-4);  // rises east: faces west
  EXPECT_NEAR(at_centre(-1.0f, 0.0f), 90.0f, 1e-4);  // rises west: faces east
  EXPECT_TRUE(std::isnan(at_centre(0.0f, 0.0f)));    // flat: no aspect
}

TEST(Derivatives, NodataStaysNodataAndNeighboursStillGetValues) {
  HeightField dem = plane(5, 5, 1.0, 0.0f, 1.0f);
  dem(2, 2) = NAN;
  const auto slope = slope_degrees(dem);
  EXPECT_TRUE(std::isnan(slope(2, 2)));
  EXPECT_FALSE(std::isnan(slope(1, 2)));
  EXPECT_FALSE(std::isnan(slope(2, 1)));
}

TEST(Derivatives, AgreeWithGdaldemOnARealDem) {
  // Mount St Helens, USGS DEM, 30 m UTM cells with nodata around its edges.
  const fs::path dem_path = fs::path(DRIFT_SOURCE_DIR) / "data" / "mount_st_helens_usgs_30m.dem";
  const fs::path dir = temp_dir();
  const HeightField dem = read_raster(dem_path);
  const HeightField ours_slope = slope_degrees(dem);
  const HeightField ours_aspect = aspect_degrees(dem);
  const HeightField gdal_slope = gdaldem(dem_path, "slope", dir / "slope.tif");
  const HeightField gdal_aspect = gdaldem(dem_path, "aspect", dir / "aspect.tif");
  ASSERT_EQ(gdal_slope.width(), dem.width());
  ASSERT_EQ(gdal_slope.height(), dem.height());

  int compared = 0, aspects = 0;
  for (int row = 0; row < dem.height(); ++row) {
    for (int x = 0; x < dem.width(); ++x) {
      if (std::isnan(dem(x, row))) {
        EXPECT_TRUE(std::isnan(ours_slope(x, row)));
        continue;
      }
      ASSERT_FALSE(std::isnan(gdal_slope(x, row))) << x << "," << row;
      EXPECT_NEAR(ours_slope(x, row), gdal_slope(x, row), 1e-3) << x << "," << row;
      ++compared;
      if (std::isnan(ours_aspect(x, row))) {
        EXPECT_TRUE(std::isnan(gdal_aspect(x, row))) << x << "," << row;
        continue;
      }
      // Angles: compare on the circle.
      const float d = std::fmod(std::abs(ours_aspect(x, row) - gdal_aspect(x, row)), 360.0f);
      EXPECT_LT(std::min(d, 360.0f - d), 1e-2f) << x << "," << row;
      ++aspects;
    }
  }
  EXPECT_GT(compared, dem.width() * dem.height() * 9 / 10);
  EXPECT_GT(aspects, compared * 9 / 10);
  fs::remove_all(dir);
}

TEST(Derivatives, PyramidHalvesAndAveragesValidCells) {
  HeightField dem(5, 4, 0.0f, local_georeference(2.0));
  for (int row = 0; row < 4; ++row)
    for (int x = 0; x < 5; ++x) dem(x, row) = static_cast<float>(x + 10 * row);
  dem(0, 0) = NAN;
  const auto levels = pyramid(dem);
  ASSERT_EQ(levels.size(), 4u);  // 5x4, 3x2, 2x1, 1x1
  EXPECT_EQ(levels[1].width(), 3);
  EXPECT_EQ(levels[1].height(), 2);
  EXPECT_DOUBLE_EQ(levels[1].geo().cell_size_x(), 4.0);
  EXPECT_DOUBLE_EQ(levels[1].geo().cell_size_y(), 4.0);
  // Block (0,0) has 3 valid cells: 1, 10, 11.
  EXPECT_FLOAT_EQ(levels[1](0, 0), (1.0f + 10.0f + 11.0f) / 3.0f);
  EXPECT_FLOAT_EQ(levels[1](1, 1), (22.0f + 23.0f + 32.0f + 33.0f) / 4.0f);
  EXPECT_FLOAT_EQ(levels[1](2, 0), (4.0f + 14.0f) / 2.0f);  // the odd column
  EXPECT_EQ(levels.back().width(), 1);
  EXPECT_EQ(levels.back().height(), 1);
}

TEST(Derivatives, PyramidKeepsTheMeanOfAnEvenGrid) {
  HeightField dem(8, 8, 0.0f, local_georeference(1.0));
  double sum = 0;
  for (int row = 0; row < 8; ++row)
    for (int x = 0; x < 8; ++x) sum += dem(x, row) = static_cast<float>((x * 37 + row * 11) % 17);
  const auto levels = pyramid(dem);
  for (const auto& level : levels) {
    double s = 0;
    for (float v : level.values()) s += v;
    EXPECT_NEAR(s / static_cast<double>(level.size()), sum / 64.0, 1e-5);
  }
}
