// drift render --map: a top-down orthographic render over the DEM whose
// files carry the DEM's CRS and a geotransform, so that it lies on the DEM in
// a GIS to the pixel (docs/rendering.md, "Maps").
#include <gtest/gtest.h>
#include <ogr_spatialref.h>

#include <cmath>
#include <limits>

#include "render/image_io.h"
#include "terrain/raster_io.h"
#include "tests/test_files.h"
#include "tests/utm_fixture.h"

namespace fs = std::filesystem;
using drift::testing::drift_log;
using drift::testing::put;
using drift::testing::run_drift;
using drift::testing::test_dir;

namespace {

// A 64 x 48 DEM of 10 m cells at UTM coordinates, gently rolling, with its
// highest cell, a 60 m spike, at column 37, row 12.
constexpr int kSpikeCol = 37, kSpikeRow = 12;
constexpr double kWest = 741003.0, kNorth = 4029640.0, kCell = 10.0;
fs::path write_dem(const fs::path& dir) {
  return drift::testing::write_dem(dir, 64, 48, kWest, kNorth, kCell, drift::testing::utm53_wkt(),
                                   [](int c, int r) {
                                     if (c == kSpikeCol && r == kSpikeRow) return 1560.0;
                                     return 1500.0 + 8.0 * std::sin(c / 7.0) * std::cos(r / 5.0);
                                   });
}

}  // namespace

TEST(MapRender, LiesOnTheDemsCellsWithItsCrs) {
  const fs::path d = test_dir("map_render");
  const fs::path dem = write_dem(d);
  put(d / "scene.toml", "[terrain]\nraster = \"dem.tif\"\n[render]\nspp = 4\n");
  ASSERT_EQ(
      run_drift("render " + (d / "scene.toml").string() + " --map -o " + (d / "map.tif").string() +
                    " -o " + (d / "map.png").string() + " -o " + (d / "map.exr").string(),
                d),
      0)
      << drift_log(d);
  // The GeoTIFF and the PNG (through its world file and .aux.xml) read back
  // with the DEM's grid and CRS, as GDAL (and so QGIS) reads them.
  const auto source = drift::terrain::read_raster(dem);
  for (const char* name : {"map.tif", "map.png"}) {
    const auto map = drift::terrain::read_raster(d / name);
    EXPECT_EQ(map.width(), 64) << name;
    EXPECT_EQ(map.height(), 48) << name;
    for (int i = 0; i < 6; ++i)
      EXPECT_NEAR(map.geo().geotransform[i], source.geo().geotransform[i], 1e-6) << name << i;
    OGRSpatialReference a, b;
    a.importFromWkt(map.geo().crs_wkt.c_str());
    b.importFromWkt(source.geo().crs_wkt.c_str());
    EXPECT_TRUE(a.IsSame(&b)) << name;
  }
  // The highest cell is the nearest to the camera above: its pixel is the
  // DEM's cell, and its P (plus the origin) lies inside that cell.
  const auto exr = drift::render::read_image(d / "map.exr");
  const int z = exr.channel_index("Z"), px = exr.channel_index("P.X");
  int best_x = -1, best_y = -1;
  float nearest = std::numeric_limits<float>::infinity();
  for (int y = 0; y < exr.height; ++y)
    for (int x = 0; x < exr.width; ++x)
      if (exr.at(x, y, z) < nearest) nearest = exr.at(x, y, z), best_x = x, best_y = y;
  EXPECT_EQ(best_x, kSpikeCol);
  EXPECT_EQ(best_y, kSpikeRow);
  std::array<float, 3> origin{};
  for (const auto& [name, v] : exr.header_vectors)
    if (name == "worldOrigin") origin = v;
  const double east = exr.at(best_x, best_y, px) + double{origin[0]};
  const double north = exr.at(best_x, best_y, px + 1) + double{origin[1]};
  EXPECT_NEAR(east, kWest + (kSpikeCol + 0.5) * kCell, 0.5 * kCell);
  EXPECT_NEAR(north, kNorth - (kSpikeRow + 0.5) * kCell, 0.5 * kCell);
}

TEST(MapRender, BoxAndCellChooseTheGridAndBadValuesAreRefused) {
  const fs::path d = test_dir("map_render");
  write_dem(d);
  put(d / "scene.toml",
      "[terrain]\nraster = \"dem.tif\"\n[render]\nspp = 1\n[camera]\nprojection = \"map\"\n"
      "map_box = [741103, 4029340, 741403, 4029540]\ncell = 20\n");
  ASSERT_EQ(run_drift("render " + (d / "scene.toml").string() + " -o " + (d / "m.tif").string(), d),
            0)
      << drift_log(d);
  const auto map = drift::terrain::read_raster(d / "m.tif");
  EXPECT_EQ(map.width(), 15);
  EXPECT_EQ(map.height(), 10);
  EXPECT_DOUBLE_EQ(map.geo().geotransform[0], 741103.0);
  EXPECT_DOUBLE_EQ(map.geo().geotransform[3], 4029540.0);
  EXPECT_DOUBLE_EQ(map.geo().geotransform[1], 20.0);
  // A .tif without a map, --size with one, a box turned inside out.
  put(d / "view.toml", "[terrain]\nraster = \"dem.tif\"\n[render]\nspp = 1\n");
  EXPECT_EQ(run_drift("render " + (d / "view.toml").string() + " -o " + (d / "v.tif").string(), d),
            1);
  EXPECT_NE(drift_log(d).find("use a .png, .exr or .json"), std::string::npos) << drift_log(d);
  EXPECT_EQ(run_drift("render " + (d / "view.toml").string() + " --map --size 8x8 -o " +
                          (d / "v.png").string(),
                      d),
            2);
  EXPECT_EQ(run_drift("render " + (d / "view.toml").string() + " --map-box 5,5,1,1 -o " +
                          (d / "v.png").string(),
                      d),
            2);
  EXPECT_FALSE(fs::exists(d / "v.png"));
  EXPECT_FALSE(fs::exists(d / "v.pgw"));
  // A box of 2e300 m: refused in a short message (it printed 301 digits).
  EXPECT_EQ(run_drift("render " + (d / "view.toml").string() +
                          " --map-box -1e300,-1e300,1e300,1e300 -o " + (d / "v.png").string(),
                      d),
            1);
  EXPECT_NE(drift_log(d).find("the map of 2e+300 x 2e+300 m"), std::string::npos) << drift_log(d);
  EXPECT_LT(drift_log(d).size(), 400u) << drift_log(d);
}
