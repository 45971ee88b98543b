// The snow-cover descriptor (paper 001, SPEC 3b): TSA against analytic
// surfaces and its invariances, the smoothing diamond, the transfer, the sun's
// side in both hemispheres, and the command line keeping the georeference.
#include "snow/snow_cover.h"

#include <gtest/gtest.h>
#include <ogr_spatialref.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "terrain/error.h"
#include "terrain/raster_io.h"
#include "tests/dem_fixture.h"

using namespace drift::snow;
using drift::terrain::HeightField;
namespace fs = std::filesystem;

namespace {

// n x n cells of `cell` metres, z = f(east, north) in metres from the centre.
template <class F>
HeightField surface(int n, double cell, F f) {
  return drift::testing::dem_from(n, cell, -(n - 1) / 2.0, f);
}

HeightField bowl(int n, double cell, double radius, double base = 0.0) {
  return surface(n, cell, [&](double e, double no) {
    const double r2 = e * e + no * no;
    return base + radius - std::sqrt(std::max(radius * radius - r2, 0.0));
  });
}

CoverOptions plain() {  // no smoothing, altitude or sun: the TSA and transfer alone
  CoverOptions o;
  o.iterations = 0;
  o.sun_range_deg = 0.0;
  o.snow_line_m = -1e6;  // everything is above the snow line
  return o;
}

// A UTM WKT for the given EPSG code.
std::string wkt_of(int epsg) {
  OGRSpatialReference srs;
  srs.importFromEPSG(epsg);
  char* text = nullptr;
  srs.exportToWkt(&text);
  std::string wkt = text;
  CPLFree(text);
  return wkt;
}

}  // namespace

TEST(Smoothing, TheDiamondHasThePapersNeighbourCount) {
  for (int n : {1, 2, 3, 7}) {
    int count = 0;
    for (int dr = -n; dr <= n; ++dr)
      for (int dx = -n; dx <= n; ++dx) count += (std::abs(dr) + std::abs(dx) <= n) && (dr || dx);
    EXPECT_EQ(smoothing_neighbour_count(n), count) << n;
    EXPECT_EQ(smoothing_neighbour_count(n), 4 * n + 2 * n * (n - 1)) << n;
  }
  // One pass on a single spike: half stays, the other half spreads evenly.
  HeightField spike(15, 15, 0.0f, drift::terrain::local_georeference(1.0));
  spike(7, 7) = 24.0f;
  const HeightField s = smooth(spike, 3);
  EXPECT_FLOAT_EQ(s(7, 7), 12.0f);
  EXPECT_FLOAT_EQ(s(7, 4), 0.5f);  // 24 / 24 neighbours / 2, at L1 distance 3
  EXPECT_FLOAT_EQ(s(5, 6), 0.5f);
  EXPECT_FLOAT_EQ(s(5, 5), 0.0f);  // L1 distance 4: outside
  double total = 0;
  for (float v : s.values()) total += v;
  EXPECT_NEAR(total, 24.0, 1e-4);  // away from the border smoothing keeps the mass
}

TEST(Accessibility, FlatPlaneIsUnboundedAndBowlGivesItsRadius) {
  const HeightField flat = surface(21, 10.0, [](double, double) { return 500.0; });
  const HeightField flat_tsa = tangent_sphere_accessibility(flat);
  for (float v : flat_tsa.values()) EXPECT_TRUE(std::isinf(v));
  // A tilted plane is flat too.
  const HeightField tilted =
      surface(21, 10.0, [](double e, double n) { return 0.3 * e - 0.2 * n; });
  EXPECT_TRUE(std::isinf(tangent_sphere_accessibility(tilted)(10, 10)));
  // A spherical bowl of radius R: the TSA near its bottom is R (the grid's
  // finite differences give a few per cent).
  const double R = 400.0;
  const HeightField b = bowl(41, 5.0, R);
  const HeightField tsa = tangent_sphere_accessibility(b);
  for (int row = 15; row <= 25; row += 5)
    for (int x = 15; x <= 25; x += 5) EXPECT_NEAR(tsa(x, row), R, 0.03 * R) << x << "," << row;
  // A dome (the bowl upside down) bounds nothing.
  HeightField dome = b;
  for (float& v : dome.values()) v = -v;
  EXPECT_TRUE(std::isinf(tangent_sphere_accessibility(dome)(20, 20)));
}

TEST(Accessibility, InvariantToHeightOffsetAndScalesWithTheTerrain) {
  const HeightField b = bowl(41, 5.0, 300.0);
  const HeightField raised = bowl(41, 5.0, 300.0, 2500.0);
  const HeightField tsa = tangent_sphere_accessibility(b);
  const HeightField tsa_raised = tangent_sphere_accessibility(raised);
  // Twice as large in every direction.
  const HeightField big = bowl(41, 10.0, 600.0);
  const HeightField tsa_big = tangent_sphere_accessibility(big);
  for (int row = 12; row <= 28; row += 4) {
    for (int x = 12; x <= 28; x += 4) {
      // Heights near 2800 m are stored to 0.25 mm: ~1 % of these 3 cm steps.
      EXPECT_NEAR(tsa_raised(x, row), tsa(x, row), 1e-2 * tsa(x, row));
      EXPECT_NEAR(tsa_big(x, row), 2.0f * tsa(x, row), 1e-3 * tsa(x, row));
    }
  }
}

TEST(Cover, NoSnowOnAFlatPlaneAndMoreInABowlAsTheProbeGrows) {
  CoverOptions o = plain();
  o.floor = 0.0;
  const HeightField flat = surface(21, 10.0, [](double, double) { return 100.0; });
  const CoverResult flat_cover = snow_cover(flat, o);
  for (float v : flat_cover.descriptor.values()) EXPECT_FLOAT_EQ(v, 1.0f);  // t = 1: bare
  const HeightField b = bowl(41, 5.0, 400.0);
  double previous = -1.0;
  // TSA 400 m: a probe of 300 m reaches in (no snow), wider ones do not.
  for (double r : {300.0, 600.0, 800.0, 1600.0}) {
    o.radius_m = r;
    const float snow = 1.0f - snow_cover(b, o).descriptor(20, 20);
    if (r < 400.0) {
      EXPECT_FLOAT_EQ(snow, 0.0f);
    } else {
      EXPECT_GT(snow, previous) << "radius " << r;
    }
    previous = snow;
  }
  EXPECT_NEAR(previous, 0.75, 2e-3);  // TSA 400 with r 1600: 1 - 400/1600
}

TEST(Cover, ShadySlopesKeepMoreSnowThanSunnyOnes) {
  // A valley (a bowl) so that there is snow to lose, tilted 20 degrees to the
  // south or to the north.
  auto valley = [](double tilt_north) {
    return surface(41, 10.0,
                   [&](double e, double n) { return 0.002 * (e * e + n * n) + tilt_north * n; });
  };
  CoverOptions o = plain();
  o.sun_range_deg = 60.0;
  o.radius_m = 5000.0;
  auto mean_snow = [&](HeightField dem, int epsg) {
    dem.geo().crs_wkt = epsg ? wkt_of(epsg) : std::string();
    dem.geo().geotransform[0] = 500000.0;  // inside the UTM zone
    dem.geo().geotransform[3] = epsg == 32754 ? 6000000.0 : 4000000.0;
    const HeightField t = snow_cover(dem, o).descriptor;
    double s = 0;
    for (int row = 10; row <= 30; ++row)
      for (int x = 10; x <= 30; ++x) s += 1.0 - t(x, row);
    return s;
  };
  // Rising to the north = facing south.
  const HeightField facing_south = valley(std::tan(20.0 * M_PI / 180.0));
  const HeightField facing_north = valley(-std::tan(20.0 * M_PI / 180.0));
  // Northern hemisphere (UTM 53N, Japan): north faces keep more snow.
  EXPECT_GT(mean_snow(facing_north, 32653), 1.2 * mean_snow(facing_south, 32653));
  // Southern hemisphere (UTM 54S): the other way round.
  EXPECT_GT(mean_snow(facing_south, 32754), 1.2 * mean_snow(facing_north, 32754));
}

TEST(Cover, RejectsBadInput) {
  const HeightField b = bowl(21, 5.0, 100.0);
  CoverOptions o;
  o.region = 0;
  EXPECT_THROW(snow_cover(b, o), drift::Error);
  o = CoverOptions{};
  HeightField holes = b;
  holes(3, 3) = NAN;
  EXPECT_THROW(snow_cover(holes, o), drift::Error);
  HeightField degrees = b;
  degrees.geo().crs_wkt = wkt_of(4326);
  EXPECT_THROW(snow_cover(degrees, o), drift::Error);
}

TEST(SnowCoverCommand, KeepsTheGeoreferenceAndRefusesNonsense) {
  const fs::path dir = fs::temp_directory_path() / "drift_snow_cover_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  HeightField dem = bowl(40, 50.0, 3000.0, 1500.0);
  dem.geo().crs_wkt = wkt_of(32653);
  dem.geo().geotransform = {600000.0, 50.0, 0.0, 4030000.0, 0.0, -50.0};
  drift::terrain::write_geotiff(dem, dir / "dem.tif");
  const std::string drift = DRIFT_EXECUTABLE;
  auto run = [&](const std::string& args) {
    return std::system((drift + " snow cover " + args + " > /dev/null 2>&1").c_str());
  };
  ASSERT_EQ(run((dir / "dem.tif").string() + " -o " + (dir / "cover.tif").string() +
                " --accessibility " + (dir / "tsa.tif").string()),
            0);
  const HeightField cover = drift::terrain::read_raster(dir / "cover.tif");
  EXPECT_EQ(cover.geo().geotransform, dem.geo().geotransform);
  OGRSpatialReference a, b;
  a.importFromWkt(cover.geo().crs_wkt.c_str());
  b.importFromWkt(dem.geo().crs_wkt.c_str());
  EXPECT_TRUE(a.IsSame(&b));
  for (float v : cover.values()) {
    EXPECT_GE(v, 0.0f);
    EXPECT_LE(v, 1.0f);
  }
  EXPECT_TRUE(fs::exists(dir / "tsa.tif"));
  EXPECT_EQ(run((dir / "dem.tif").string() + " -o " + (dir / "x.tif").string() + " --region 0"),
            2 << 8);
  EXPECT_EQ(run((dir / "dem.tif").string() + " -o " + (dir / "x.tif").string() +
                " --radius 100 --radius-cells 3"),
            2 << 8);
  EXPECT_EQ(run((dir / "missing.tif").string() + " -o " + (dir / "x.tif").string()), 1 << 8);
  EXPECT_FALSE(fs::exists(dir / "x.tif"));
  fs::remove_all(dir);
}
