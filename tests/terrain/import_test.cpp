// DEM import: reprojection to UTM with metric cells, nodata fill, crop, and the
// command line's behaviour on bad input.
#include "terrain/import.h"

#include <gtest/gtest.h>
#include <ogr_spatialref.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "terrain/error.h"
#include "terrain/raster_io.h"

namespace fs = std::filesystem;
using namespace drift::terrain;

namespace {
fs::path data(const char* name) { return fs::path(DRIFT_SOURCE_DIR) / "data" / name; }

int epsg_of(const HeightField& g) {
  OGRSpatialReference srs;
  srs.importFromWkt(g.geo().crs_wkt.c_str());
  srs.AutoIdentifyEPSG();
  const char* code = srs.GetAuthorityCode(nullptr);
  return code ? std::atoi(code) : 0;
}
}  // namespace

TEST(Import, GeographicDemBecomesUtmWithMetricCells) {
  // Yarigatake: 0.4" cells are ~10.0 m E-W and ~12.3 m N-S at 36.4 N (data/SOURCES.md).
  const ImportResult r = import_dem(data("yarigatake_gsi_dem10b_jgd2000.tif"), {});
  EXPECT_EQ(epsg_of(r.grid), 32653);  // UTM zone 53N
  EXPECT_NEAR(r.grid.geo().cell_size_x(), 9.97, 0.05);
  EXPECT_DOUBLE_EQ(r.grid.geo().cell_size_x(), r.grid.geo().cell_size_y());
  float hi = -1e9f;
  for (float v : r.grid.values()) {
    ASSERT_FALSE(std::isnan(v));
    hi = std::max(hi, v);
  }
  EXPECT_NEAR(hi, 3181.4f, 5.0f) << "the summit survives bilinear warping";
}

TEST(Import, UtmZoneFromLonLat) {
  EXPECT_EQ(utm_epsg(137.69, 36.37), 32653);
  EXPECT_EQ(utm_epsg(-118.3, 36.5), 32611);
  EXPECT_EQ(utm_epsg(151.2, -33.9), 32756);  // Sydney: southern hemisphere
}

TEST(Import, ProjectedDemKeepsCrsAndFillsNodata) {
  // St Helens: UTM 10N (NAD27), 30 m, 4151 nodata cells (data/SOURCES.md).
  const ImportResult r = import_dem(data("mount_st_helens_usgs_30m.dem"), {});
  EXPECT_EQ(r.grid.width(), 327);
  EXPECT_EQ(r.grid.height(), 468);
  EXPECT_EQ(r.filled_cells, 4151u);
  EXPECT_EQ(epsg_of(r.grid), 26710);
}

TEST(Import, CropByLonLatBox) {
  ImportOptions o;
  o.crop_lonlat = std::array<double, 4>{-118.4, 36.5, -118.2, 36.65};
  const ImportResult r = import_dem(data("N36W119.hgt"), o);
  // 0.2 deg x 0.15 deg at 36.6 N is about 17.9 km x 16.6 km; cells ~74.7 m.
  EXPECT_NEAR(r.grid.width() * r.grid.geo().cell_size_x(), 17900, 600);
  EXPECT_NEAR(r.grid.height() * r.grid.geo().cell_size_y(), 16650, 600);
}

TEST(Import, CropByBoxInTheDemsOwnCrs) {
  // St Helens in its UTM 10N metres: a 3 km x 2.4 km box on whole 30 m cells.
  const ImportResult full = import_dem(data("mount_st_helens_usgs_30m.dem"), {});
  const auto& gt = full.grid.geo().geotransform;
  const double x0 = gt[0] + 60 * 30.0, y1 = gt[3] - 90 * 30.0;
  ImportOptions o;
  o.crop = std::array<double, 4>{x0, y1 - 2400.0, x0 + 3000.0, y1};
  const ImportResult r = import_dem(data("mount_st_helens_usgs_30m.dem"), o);
  EXPECT_EQ(r.grid.width(), 100);
  EXPECT_EQ(r.grid.height(), 80);
  EXPECT_DOUBLE_EQ(r.grid.geo().geotransform[0], x0);
  EXPECT_DOUBLE_EQ(r.grid.geo().geotransform[3], y1);
  EXPECT_EQ(epsg_of(r.grid), 26710);
  // Same heights as the uncropped import, cell for cell.
  for (int row = 0; row < r.grid.height(); row += 7) {
    for (int x = 0; x < r.grid.width(); x += 9) {
      EXPECT_FLOAT_EQ(r.grid(x, row), full.grid(x + 60, row + 90)) << x << "," << row;
    }
  }
}

TEST(Import, KeepCrsLeavesAGeographicDemInDegrees) {
  ImportOptions o;
  o.keep_crs = true;
  const ImportResult r = import_dem(data("mount_whitney_srtm3_crop.asc"), o);
  EXPECT_LT(r.grid.geo().cell_size_x(), 0.01);  // still degrees (3 arc-seconds)
  OGRSpatialReference srs;
  srs.importFromWkt(r.grid.geo().crs_wkt.c_str());
  EXPECT_TRUE(srs.IsGeographic());
}

TEST(Import, ResampleAndExaggerate) {
  ImportOptions o;
  o.resample_m = 60.0;
  o.exaggeration = 2.0;
  const ImportResult base = import_dem(data("mount_st_helens_usgs_30m.dem"), {});
  const ImportResult r = import_dem(data("mount_st_helens_usgs_30m.dem"), o);
  EXPECT_DOUBLE_EQ(r.grid.geo().cell_size_x(), 60.0);
  EXPECT_NEAR(r.grid.width(), 327 / 2, 1);
  float hi_base = -1e9f, hi = -1e9f;
  for (float v : base.grid.values()) hi_base = std::max(hi_base, v);
  for (float v : r.grid.values()) hi = std::max(hi, v);
  EXPECT_NEAR(hi, 2.0f * hi_base, 0.05f * hi_base);
}

TEST(Import, AllNodataIsAnError) {
  HeightField g(4, 4, std::nanf(""));
  EXPECT_THROW(fill_nodata(g, "test grid"), drift::Error);
}

TEST(Import, FillNodataIsLocalAndComplete) {
  HeightField g(5, 5, 10.0f);
  g(2, 2) = std::nanf("");
  g(0, 0) = std::nanf("");
  EXPECT_EQ(fill_nodata(g, "g"), 2u);
  EXPECT_FLOAT_EQ(g(2, 2), 10.0f);
  EXPECT_FLOAT_EQ(g(0, 0), 10.0f);
}

namespace {

// The fill by a pass over the whole grid per ring (quadratic in a gap's
// width): the reference for the bits of the walk in terrain/import.cpp.
void fill_by_passes(HeightField& g) {
  std::size_t missing = 0;
  for (float v : g.values()) missing += std::isnan(v);
  while (missing > 0) {
    HeightField next = g;
    for (int r = 0; r < g.height(); ++r)
      for (int x = 0; x < g.width(); ++x) {
        if (!std::isnan(g(x, r))) continue;
        double sum = 0;
        int count = 0;
        for (int dr = -1; dr <= 1; ++dr)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, rr = r + dr;
            if (xx < 0 || rr < 0 || xx >= g.width() || rr >= g.height()) continue;
            if (!std::isnan(g(xx, rr))) sum += g(xx, rr), ++count;
          }
        if (count > 0) next(x, r) = static_cast<float>(sum / count), --missing;
      }
    g = std::move(next);
  }
}

}  // namespace

TEST(Import, FillNodataGivesTheBitsOfFillingRingByRing) {
  HeightField g(53, 41, 0.0f);
  std::uint32_t state = 12345;
  for (int r = 0; r < g.height(); ++r)
    for (int x = 0; x < g.width(); ++x) {
      state = state * 1664525u + 1013904223u;
      const bool hole = (x - 30) * (x - 30) + (r - 20) * (r - 20) < 150 || (state >> 24) < 90;
      g(x, r) = hole ? std::nanf("") : static_cast<float>(state >> 8) * 1e-3f;
    }
  HeightField reference = g;
  std::size_t holes = 0;
  for (float v : g.values()) holes += std::isnan(v);
  fill_by_passes(reference);
  EXPECT_EQ(fill_nodata(g, "g"), holes);
  EXPECT_TRUE(g.values() == reference.values());
}

// A gap a million cells long fills in one walk; filled a pass per ring it took
// 10^12 cell visits (the suite's timeout stops that).
TEST(Import, FillNodataIsLinearInAGapsWidth) {
  HeightField g(1, 1000000, std::nanf(""));
  g(0, 0) = 7.0f;
  EXPECT_EQ(fill_nodata(g, "strip"), 999999u);
  EXPECT_EQ(g(0, 999999), 7.0f);
}

// A strip of degrees near a UTM zone's edge lies slanted after reprojection:
// its warped grid is the slanted strip's box (150 million cells here), not its
// own 4 x 80,000; found by fuzz_raster when GDAL allocated 603 MB unchecked.
TEST(Import, ReprojectedGridIsCheckedAtItsWarpedExtent) {
  OGRSpatialReference wgs84;
  wgs84.importFromEPSG(4326);
  char* wkt = nullptr;
  wgs84.exportToWkt(&wkt);
  GeoReference geo;
  geo.crs_wkt = wkt;
  CPLFree(wkt);
  geo.geotransform = {137.6, 1e-4, 0.0, 36.4, 0.0, -1e-4};
  HeightField strip(4, 65535, 1000.0f, geo);
  const fs::path file = fs::temp_directory_path() / "drift_import_slanted_strip.tif";
  write_geotiff(strip, file);
  setenv("DRIFT_MEMORY_LIMIT", "256M", 1);
  try {
    import_dem(file, {});
    ADD_FAILURE() << "imported";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("importing '" + file.string()), std::string::npos)
        << e.what();
  }
  unsetenv("DRIFT_MEMORY_LIMIT");
  fs::remove(file);
}

// GDAL reads a pixel-interleaved row across every band at once: 1.3 GiB for
// this 457-byte TIFF of 63,233 bands (fuzz_raster), checked before reading.
TEST(Import, RowAcrossEveryBandIsCheckedBeforeReading) {
  setenv("DRIFT_MEMORY_LIMIT", "64M", 1);
  const fs::path file =
      fs::path(DRIFT_SOURCE_DIR) / "tests/fuzz/regressions/raster/row_across_63233_bands.tif";
  try {
    import_dem(file, {});
    ADD_FAILURE() << "imported";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("across its 63233 bands"), std::string::npos) << e.what();
  }
  unsetenv("DRIFT_MEMORY_LIMIT");
}

TEST(ImportCommand, MissingFileExitsOneAndWritesNothing) {
  const fs::path out = fs::temp_directory_path() / "drift_import_missing.tif";
  fs::remove(out);
  const std::string cmd = std::string(DRIFT_EXECUTABLE) + " import /nonexistent.tif -o " +
                          out.string() + " 2>/dev/null";
  EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 1);
  EXPECT_FALSE(fs::exists(out));
}

TEST(ImportCommand, WritesAUtmGeoTiff) {
  const fs::path out = fs::temp_directory_path() / "drift_import_ok.tif";
  const std::string cmd = std::string(DRIFT_EXECUTABLE) + " import " +
                          data("jacksboro_fault_tn_3arcsec.tif").string() + " -o " + out.string() +
                          " >/dev/null";
  ASSERT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 0);
  const HeightField g = read_raster(out);
  EXPECT_EQ(epsg_of(g), 32616);  // 84.2 W -> UTM zone 16N
}
