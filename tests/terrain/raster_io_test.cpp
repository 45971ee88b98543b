#include "terrain/raster_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "terrain/error.h"

namespace fs = std::filesystem;
using drift::terrain::HeightField;

namespace {

fs::path data(const char* name) { return fs::path(DRIFT_SOURCE_DIR) / "data" / name; }

fs::path scratch(const char* name) {
  fs::path dir = fs::temp_directory_path() / "drift_tests";
  fs::create_directories(dir);
  return dir / name;
}

}  // namespace

TEST(RasterIo, ReadsYarigatakeGeoTiff) {
  HeightField dem = drift::terrain::read_raster(data("yarigatake_gsi_dem10b_jgd2000.tif"));
  EXPECT_EQ(dem.width(), 1125);
  EXPECT_EQ(dem.height(), 750);
  float hi = -1e9f;
  for (float v : dem.values()) hi = std::max(hi, v);
  EXPECT_NEAR(hi, 3181.4f, 0.1f);  // Yarigatake summit, data/SOURCES.md
  EXPECT_NE(dem.geo().crs_wkt.find("JGD2000"), std::string::npos);
}

TEST(RasterIo, NodataBecomesNaN) {
  // St Helens quadrangle: 4151 nodata cells at the edges (data/SOURCES.md).
  HeightField dem = drift::terrain::read_raster(data("mount_st_helens_usgs_30m.dem"));
  std::size_t nan = 0;
  for (float v : dem.values()) nan += std::isnan(v);
  EXPECT_EQ(nan, 4151u);
}

TEST(RasterIo, GeoTiffRoundTripKeepsValuesAndGeoreference) {
  HeightField dem = drift::terrain::read_raster(data("jacksboro_fault_tn_3arcsec.tif"));
  const fs::path out = scratch("roundtrip.tif");
  drift::terrain::write_geotiff(dem, out, {"height", "m"});
  HeightField back = drift::terrain::read_raster(out);
  ASSERT_EQ(back.width(), dem.width());
  ASSERT_EQ(back.height(), dem.height());
  EXPECT_EQ(back.values(), dem.values());
  for (int i = 0; i < 6; ++i) {
    EXPECT_DOUBLE_EQ(back.geo().geotransform[i], dem.geo().geotransform[i]) << "term " << i;
  }
  EXPECT_NE(back.geo().crs_wkt.find("WGS 84"), std::string::npos);
}

TEST(RasterIo, MissingFileIsAClearError) {
  try {
    drift::terrain::read_raster("/nonexistent/dem.tif");
    FAIL() << "no error";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dem.tif"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos);
  }
}

TEST(RasterIo, NonRasterIsAClearError) {
  const fs::path bogus = scratch("not_a_raster.tif");
  std::ofstream(bogus) << "this is not a raster\n";
  EXPECT_THROW(drift::terrain::read_raster(bogus), drift::Error);
}

TEST(RasterIo, TruncatedGeoTiffIsAClearError) {
  const fs::path src = data("yarigatake_gsi_dem10b_jgd2000.tif");
  const fs::path cut = scratch("truncated.tif");
  {
    std::ifstream in(src, std::ios::binary);
    std::vector<char> bytes(fs::file_size(src) / 2);
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    std::ofstream(cut, std::ios::binary)
        .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  EXPECT_THROW(drift::terrain::read_raster(cut), drift::Error);
}

TEST(RasterIo, FailedWriteLeavesExistingFileUntouched) {
  const fs::path out = scratch("keep.tif");
  std::ofstream(out) << "good";
  HeightField empty;
  EXPECT_THROW(drift::terrain::write_geotiff(empty, out), drift::Error);
  std::ifstream in(out);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "good");
}

TEST(RasterIo, RasterLargerThanMemoryIsRefusedBeforeReading) {
  // A 200000 x 200000 float32 raster (160 GB) described by a tiny VRT: the read
  // must be refused up front, naming the file and the fix, never attempted.
  const fs::path vrt = scratch("huge.vrt");
  std::ofstream(vrt) << "<VRTDataset rasterXSize=\"200000\" rasterYSize=\"200000\">\n"
                        "  <VRTRasterBand dataType=\"Float32\" band=\"1\"/>\n"
                        "</VRTDataset>\n";
  try {
    drift::terrain::read_raster(vrt);
    FAIL() << "no error";
  } catch (const drift::Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("huge.vrt"), std::string::npos) << m;
    EXPECT_NE(m.find("crop"), std::string::npos) << m;
  }
}
