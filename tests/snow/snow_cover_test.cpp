// The snow-cover descriptor (paper 001; docs/snow.md): TSA against analytic
// surfaces and its invariances, the smoothing diamond, the transfer, the sun's
// side in both hemispheres, and the command line keeping the georeference.
#include "snow/snow_cover.h"

#include <gtest/gtest.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>

#include "terrain/error.h"
#include "terrain/raster_io.h"
#include "tests/dem_fixture.h"
#include "tests/utm_fixture.h"

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

CoverOptions plain_with_radius(double radius_m) {
  CoverOptions o = plain();
  o.radius_m = radius_m;
  return o;
}

using drift::testing::wkt_of_epsg;

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

// The smoothing as the paper states it, each diamond summed cell by cell in
// the same exact fixed point (heights as integers of 2^-32 m): the O(1)
// diagonal sums must give these bits.
HeightField smooth_reference(const HeightField& dem, int n) {
  HeightField out(dem.width(), dem.height(), 0.0f, dem.geo());
  const auto fixed = [](float v) { return static_cast<std::int64_t>(double(v) * 4294967296.0); };
  for (int row = 0; row < dem.height(); ++row)
    for (int x = 0; x < dem.width(); ++x) {
      __extension__ __int128 sum = 0;
      for (int dr = -n; dr <= n; ++dr)
        for (int dc = -(n - std::abs(dr)); dc <= n - std::abs(dr); ++dc)
          if (dr || dc)
            sum += fixed(dem(std::clamp(x + dc, 0, dem.width() - 1),
                             std::clamp(row + dr, 0, dem.height() - 1)));
      const double mean = double(sum) / 4294967296.0 / smoothing_neighbour_count(n);
      out(x, row) = static_cast<float>(0.5 * (dem(x, row) + mean));
    }
  return out;
}

TEST(Smoothing, DiagonalSumsGiveTheDirectDiamondSumsBitForBit) {
  // Random heights from 0.1 mm to 5 km (the fixed point's full range of
  // bits), rasters narrower and wider than the diamond, and tall enough for
  // several strips of rows; radii from 1 to 40 cells.
  std::mt19937 rng(36);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{61, 150}, std::pair{200, 211}}) {
    HeightField dem(w, h, 0.0f, drift::terrain::local_georeference(10.0));
    for (float& v : dem.values()) {
      const float u = unit(rng);
      v = u < 0.2f ? 1e-4f * unit(rng) : 5000.0f * unit(rng);
    }
    for (int n : {1, 2, 3, 7, 15, 40}) {
      SCOPED_TRACE(std::to_string(w) + " x " + std::to_string(h) + ", n " + std::to_string(n));
      const HeightField fast = smooth(dem, n), slow = smooth_reference(dem, n);
      int differ = 0;
      for (std::size_t i = 0; i < fast.size(); ++i)
        differ += std::memcmp(&fast.values()[i], &slow.values()[i], sizeof(float)) != 0;
      EXPECT_EQ(differ, 0);
    }
  }
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
    dem.geo().crs_wkt = epsg ? wkt_of_epsg(epsg) : std::string();
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
  // Northern hemisphere (UTM 53N, Japan): north faces keep more snow; the
  // paper's per-triangle rule leaves the south face 4.3 times barer here (the
  // mean of phi over the 12 triangles: 1.8 times, which fails this test).
  const double north_ratio = mean_snow(facing_north, 32653) / mean_snow(facing_south, 32653);
  // Southern hemisphere (UTM 54S): the other way round.
  const double south_ratio = mean_snow(facing_south, 32754) / mean_snow(facing_north, 32754);
  std::printf("north/south snow %.2f (northern), %.2f (southern)\n", north_ratio, south_ratio);
  EXPECT_GT(north_ratio, 4.0);
  EXPECT_GT(south_ratio, 4.0);
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
  degrees.geo().crs_wkt = wkt_of_epsg(4326);
  EXPECT_THROW(snow_cover(degrees, o), drift::Error);
}

TEST(SnowCoverCommand, KeepsTheGeoreferenceAndRefusesNonsense) {
  const fs::path dir = fs::temp_directory_path() / "drift_snow_cover_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  HeightField dem = bowl(40, 50.0, 3000.0, 1500.0);
  dem.geo().crs_wkt = wkt_of_epsg(32653);
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

TEST(Cover, AltitudeFactorIsQuadraticInHeightOrASnowLine) {
  // A spherical bowl: TSA = R near its bottom, so g = R / r there.
  const double R = 400.0, r = 1600.0;
  CoverOptions o = plain();
  o.radius_m = r;
  o.snow_line_m.reset();  // (z / z_max)^2
  const HeightField b = bowl(41, 5.0, R, 1000.0);
  float z_max = 0.0f;
  for (float v : b.values()) z_max = std::max(z_max, v);
  const double a = b(20, 20) / z_max;
  EXPECT_NEAR(1.0 - snow_cover(b, o).descriptor(20, 20), (1.0 - R / r) * a * a, 0.01);
  // A snow line: all below it bare, all well above it as much as the transfer gives,
  // half way at the line (a smooth step over the band).
  const double z = b(20, 20);
  for (auto [line, expected] : {std::pair{z + 500.0, 0.0}, {z - 500.0, 1.0}, {z, 0.5}}) {
    o.snow_line_m = line;
    EXPECT_NEAR(1.0 - snow_cover(b, o).descriptor(20, 20), (1.0 - R / r) * expected, 0.01) << line;
  }
}

TEST(Cover, DescriptorIsTheTransferTimesAltitudeSmoothedOnce) {
  // Rough ground so that t varies from cell to cell; no smoothing of the DEM, no sun.
  const HeightField dem = surface(48, 20.0, [](double e, double n) {
    return 2000.0 + 0.0004 * (e * e + n * n) + 30.0 * std::sin(e / 37.0) * std::cos(n / 23.0);
  });
  CoverOptions o = plain();
  o.snow_line_m.reset();
  o.radius_m = 800.0;
  const CoverResult res = snow_cover(dem, o);
  float z_max = 0.0f;
  for (float v : dem.values()) z_max = std::max(z_max, v);
  HeightField raw(dem.width(), dem.height(), 0.0f, dem.geo());
  for (int row = 0; row < dem.height(); ++row)
    for (int x = 0; x < dem.width(); ++x) {
      const float tsa = res.accessibility(x, row);
      const float g = tsa >= 800.0f ? 1.0f : tsa / 800.0f;
      const float a = dem(x, row) / z_max;
      raw(x, row) = 1.0f - (1.0f - g) * a * a;
    }
  const HeightField expected = smooth(raw, 1);
  double largest_step = 0.0;
  for (int row = 0; row < dem.height(); ++row)
    for (int x = 0; x < dem.width(); ++x) {
      EXPECT_NEAR(res.descriptor(x, row), expected(x, row), 1e-5) << x << "," << row;
      if (x > 0)
        largest_step =
            std::max(largest_step, std::abs(static_cast<double>(raw(x, row) - raw(x - 1, row))));
    }
  EXPECT_GT(largest_step, 0.05);  // t does vary: the smoothing is seen
}

// A bowl tilted by 25 degrees to face `facing_deg` (clockwise from north): near its
// bottom the 12 triangles all face about that way.
HeightField tilted_bowl(double facing_deg) {
  const double f = facing_deg * M_PI / 180.0, s = std::tan(25.0 * M_PI / 180.0);
  return surface(41, 10.0, [&](double e, double n) {
    return 1000.0 + 0.002 * (e * e + n * n) - s * (e * std::sin(f) + n * std::cos(f));
  });
}

TEST(Cover, SunStepUpdatesTOncePerFacingTriangleAsThePaperWrites) {
  CoverOptions o = plain();
  o.radius_m = 5000.0;
  const HeightField south_east = tilted_bowl(150.0);  // 30 degrees east of south
  const float no_sun = 1.0f - snow_cover(south_east, o).descriptor(20, 20);
  ASSERT_GT(no_sun, 0.1f);
  o.sun_range_deg = 60.0;  // phi = 30 / 60 = 0.5 for every triangle
  const float per_triangle = 1.0f - snow_cover(south_east, o).descriptor(20, 20);
  o.sun_step = SunStep::Mean;
  const float mean = 1.0f - snow_cover(south_east, o).descriptor(20, 20);
  // Paper lines 10-15: t = t phi + (1 - phi) for each of the 12: snow x phi^12.
  EXPECT_NEAR(per_triangle / no_sun, std::pow(0.5, 12), 0.5 * std::pow(0.5, 12));
  EXPECT_NEAR(mean / no_sun, 0.5, 0.03);
  // A north face is untouched by either rule; due south loses everything.
  o.sun_step = SunStep::PerTriangle;
  EXPECT_FLOAT_EQ(
      1.0f - snow_cover(tilted_bowl(0.0), o).descriptor(20, 20),
      1.0f - snow_cover(tilted_bowl(0.0), plain_with_radius(5000.0)).descriptor(20, 20));
  EXPECT_NEAR(1.0f - snow_cover(tilted_bowl(180.0), o).descriptor(20, 20), 0.0f, 1e-6f);
}

// Pearson correlation of two equally long sequences.
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
  ma /= a.size(), mb /= b.size();
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    sab += (a[i] - ma) * (b[i] - mb), saa += (a[i] - ma) * (a[i] - ma),
        sbb += (b[i] - mb) * (b[i] - mb);
  return sab / std::sqrt(saa * sbb);
}

TEST(Cover, MetricDefaultsGiveTheSameDescriptorOnADemResampledFiveTimesFiner) {
  // A 6 km range of ridges and valleys at the paper's 50 m ...
  const int n = 120;
  HeightField coarse(n, n, 0.0f, drift::terrain::local_georeference(50.0));
  for (int row = 0; row < n; ++row)
    for (int x = 0; x < n; ++x) {
      const double e = x * 50.0, no = row * 50.0;
      coarse(x, row) =
          static_cast<float>(1500.0 + 700.0 * std::sin(e / 900.0) * std::cos(no / 700.0) +
                             250.0 * std::sin(e / 310.0 + no / 410.0) +
                             90.0 * std::sin(e / 130.0) * std::cos(no / 170.0));
    }
  // ... and the same DEM resampled bilinearly to 10 m (coarse cell centres on fine ones).
  const int k = 5;
  HeightField fine(n * k, n * k, 0.0f, drift::terrain::local_georeference(10.0));
  for (int row = 0; row < n * k; ++row)
    for (int x = 0; x < n * k; ++x) {
      const double cx = std::clamp((x - 2) / double(k), 0.0, n - 1.0);
      const double cr = std::clamp((row - 2) / double(k), 0.0, n - 1.0);
      const int x0 = std::min(static_cast<int>(cx), n - 2),
                r0 = std::min(static_cast<int>(cr), n - 2);
      const double tx = cx - x0, tr = cr - r0;
      fine(x, row) =
          static_cast<float>((1 - tr) * ((1 - tx) * coarse(x0, r0) + tx * coarse(x0 + 1, r0)) +
                             tr * ((1 - tx) * coarse(x0, r0 + 1) + tx * coarse(x0 + 1, r0 + 1)));
    }
  auto agreement = [&](const CoverOptions& on_fine) {
    const HeightField a = snow_cover(coarse, CoverOptions{}).descriptor;
    const HeightField b = snow_cover(fine, on_fine).descriptor;
    std::vector<double> va, vb;
    for (int row = 4; row < n - 4; ++row)  // away from the clamped border
      for (int x = 4; x < n - 4; ++x)
        va.push_back(a(x, row)), vb.push_back(b(k * x + 2, k * row + 2));
    return correlation(va, vb);
  };
  const double metric = agreement(CoverOptions{});
  CoverOptions cells;  // the paper's numbers taken as cells of the finer DEM
  cells.region_cells = 3;
  cells.radius_cells = 55.0;
  const double in_cells = agreement(cells);
  std::printf("descriptor at 50 m against 10 m: correlation %.3f (metric defaults), %.3f (cells)\n",
              metric, in_cells);
  EXPECT_GT(metric, 0.8);
  EXPECT_GT(metric, in_cells + 0.1);
}
