// The small shared ideas every module draws on (terrain/bilinear.h,
// terrain/direction.h, terrain/hash.h, terrain/local_frame.h, terrain/angles.h,
// terrain/neighbours.h, terrain/height_change.h, the meridian convergence of
// terrain/geodesy.h and the central differences of terrain/derivatives.h),
// against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "terrain/angles.h"
#include "terrain/bilinear.h"
#include "terrain/derivatives.h"
#include "terrain/direction.h"
#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/hash.h"
#include "terrain/height_change.h"
#include "terrain/local_frame.h"
#include "terrain/neighbours.h"

using namespace drift::terrain;

namespace {

// z = 3 + 2 x - 5 row on a 4 x 3 grid: bilinear interpolation is exact on it.
HeightField ramp() {
  HeightField g(4, 3);
  for (int row = 0; row < 3; ++row)
    for (int x = 0; x < 4; ++x) g(x, row) = static_cast<float>(3 + 2 * x - 5 * row);
  return g;
}

}  // namespace

TEST(Bilinear, ReproducesAffineFieldsAndClampsAtTheBorder) {
  const HeightField g = ramp();
  for (double x : {0.0, 0.25, 1.5, 2.75, 3.0})
    for (double r : {0.0, 0.5, 1.2, 2.0})
      EXPECT_NEAR(bilinear_clamped(g, x, r), 3 + 2 * x - 5 * r, 1e-5) << x << ", " << r;
  // Beyond the border the edge holds.
  EXPECT_FLOAT_EQ(bilinear_clamped(g, -4.0, -1.0), g(0, 0));
  EXPECT_FLOAT_EQ(bilinear_clamped(g, 9.0, 7.0), g(3, 2));
  // A saddle, z = x y on the unit square: (1/2)(1/2) at the centre.
  EXPECT_DOUBLE_EQ(bilinear_blend(0.0, 0.0, 0.0, 1.0, 0.5, 0.5), 0.25);
  EXPECT_DOUBLE_EQ(bilinear_blend(0.0, 0.0, 0.0, 1.0, 0.3, 0.9), 0.3 * 0.9);
}

TEST(Bilinear, OneWideGridsReadTheirOnlyColumn) {
  HeightField g(1, 2);
  g(0, 0) = 1.0f;
  g(0, 1) = 3.0f;
  EXPECT_FLOAT_EQ(bilinear_clamped(g, 0.7, 0.5), 2.0f);
}

TEST(Direction, AzimuthClockwiseFromNorthElevationUp) {
  const auto near = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return (a - b).norm() < 1e-12;
  };
  EXPECT_TRUE(near(direction_from_az_el(0, 0), {0, 1, 0}));   // north
  EXPECT_TRUE(near(direction_from_az_el(90, 0), {1, 0, 0}));  // east
  EXPECT_TRUE(near(direction_from_az_el(180, 0), {0, -1, 0}));
  EXPECT_TRUE(near(direction_from_az_el(123, 90), {0, 0, 1}));
  const Eigen::Vector3d d = direction_from_az_el(225, 30);
  EXPECT_NEAR(d.norm(), 1.0, 1e-15);
  EXPECT_NEAR(d.z(), 0.5, 1e-15);
  EXPECT_NEAR(d.x(), d.y(), 1e-15);
  EXPECT_LT(d.x(), 0);
}

TEST(Hash, SplitMix64KnownValuesAndUniformRanges) {
  // SplitMix64 seeded with 0 yields 0xe220a8397b1dcdaf first (Vigna's reference
  // code): mix64 is its finaliser applied to the first increment.
  EXPECT_EQ(mix64(0), 0xe220a8397b1dcdafULL);
  std::set<std::uint64_t> seen;
  double sum = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const std::uint64_t bits = mix64(mix64(7) ^ i);
    seen.insert(bits);
    const double u = unit_double(bits);
    const float f = unit_float(bits);
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    ASSERT_GE(f, 0.0f);
    ASSERT_LT(f, 1.0f);
    sum += u;
  }
  EXPECT_EQ(seen.size(), static_cast<std::size_t>(n));
  EXPECT_NEAR(sum / n, 0.5, 0.005);  // 5 standard errors of the mean
  EXPECT_EQ(unit_double(~0ULL), 1.0 - 0x1.0p-53);
  EXPECT_EQ(unit_float(~0ULL), 1.0f - 0x1.0p-24f);
}

TEST(LocalFrame, OriginAtTheCentreCellAndLowestValidHeight) {
  HeightField g(3, 5, 10.0f, local_georeference(2.0));
  g.geo().geotransform[0] = 500000;
  g.geo().geotransform[3] = 4000000;
  g(0, 0) = NAN;
  g(2, 4) = 4.0f;
  g(1, 1) = 12.0f;
  const LocalFrame f = local_frame(g, "the test raster", 2.0);
  EXPECT_EQ(f.lowest, 4.0f);
  EXPECT_EQ(f.highest, 12.0f);
  EXPECT_DOUBLE_EQ(f.origin.x(), 500000 + 3.0);  // the centre of cell (1, 2)
  EXPECT_DOUBLE_EQ(f.origin.y(), 4000000 - 5.0);
  EXPECT_DOUBLE_EQ(f.origin.z(), 8.0);  // lowest x z_scale
  EXPECT_DOUBLE_EQ(f.x0, -2.0);         // cell (0, 0)'s centre, from the origin
  EXPECT_DOUBLE_EQ(f.y0, 4.0);
  HeightField empty(2, 2, NAN);
  try {
    local_frame(empty, "the test raster");
    FAIL() << "an all-nodata raster must be refused";
  } catch (const drift::Error& e) {
    EXPECT_STREQ(e.what(), "the test raster holds no valid height (all nodata)");
  }
}

TEST(CentralGradient, ExactOnPlanesInsideAndAtTheBorder) {
  // z = 0.5 east + 0.25 north with 2 m x 4 m cells: rows run south.
  HeightField g(5, 4);
  for (int row = 0; row < 4; ++row)
    for (int x = 0; x < 5; ++x) g(x, row) = static_cast<float>(0.5 * 2 * x - 0.25 * 4 * row);
  for (int row = 0; row < 4; ++row)
    for (int x = 0; x < 5; ++x) {
      const Eigen::Vector2d d = central_gradient(g, 5, 4, 2.0, 4.0, x, row);
      EXPECT_DOUBLE_EQ(d.x(), 0.5) << x << ", " << row;
      EXPECT_DOUBLE_EQ(d.y(), 0.25) << x << ", " << row;
    }
  const Eigen::Vector3d n = normal_from_gradient({0.5, 0.25});
  EXPECT_NEAR(n.norm(), 1.0, 1e-15);
  EXPECT_NEAR(n.dot(Eigen::Vector3d(1, 0, 0.5)), 0.0, 1e-15);  // perpendicular to the slope
  EXPECT_GT(n.z(), 0);
}

TEST(Angles, DegreesAndRadiansRoundTripAndMatchTheClosedForms) {
  EXPECT_DOUBLE_EQ(radians(180.0), std::acos(-1.0));
  EXPECT_DOUBLE_EQ(degrees(std::acos(-1.0) / 2.0), 90.0);
  EXPECT_FLOAT_EQ(radians(90.0f), static_cast<float>(std::acos(-1.0) / 2.0));
  EXPECT_NEAR(tan_degrees(45.0), 1.0, 1e-15);
  for (double d : {-720.0, -33.3, 0.0, 12.5, 359.0}) EXPECT_NEAR(degrees(radians(d)), d, 1e-12);
}

TEST(Neighbours, EightOffsetsEachOppositeItsMirror) {
  std::set<std::pair<int, int>> seen;
  for (int k = 0; k < 8; ++k) {
    const NeighbourOffset o = kNeighbours8[k], m = kNeighbours8[opposite_neighbour(k)];
    EXPECT_EQ(o.dx, -m.dx);
    EXPECT_EQ(o.dy, -m.dy);
    EXPECT_TRUE(o.dx != 0 || o.dy != 0);
    seen.insert({o.dx, o.dy});
  }
  EXPECT_EQ(seen.size(), 8u);
}

// One nodata rule: a NaN ground stays NaN; a change with no data leaves the
// ground as it is; sizes must agree.
TEST(HeightChange, LaysAChangeOnTheGroundWithOneNodataRule) {
  HeightField ground(3, 1, 100.0f), change(3, 1, 0.5f);
  ground(0, 0) = NAN;
  change(1, 0) = NAN;
  change(2, 0) = INFINITY;
  const HeightField top = lay_on_ground(ground, change);
  EXPECT_TRUE(std::isnan(top(0, 0)));
  EXPECT_EQ(top(1, 0), 100.0f);
  EXPECT_EQ(top(2, 0), 100.0f);
  change(2, 0) = 0.25f;
  EXPECT_EQ(lay_on_ground(ground, change)(2, 0), 100.25f);
  EXPECT_THROW(lay_on_ground(ground, HeightField(2, 1, 0.0f)), drift::Error);
}

// UTM zone 54N (central meridian 141 E) at 137.5 E, 36.3 N: west of the
// central meridian the meridians lean east going north, so true north lies
// clockwise of grid north by about (lon0 - lon) sin(lat) = 3.5 x 0.592 degrees.
TEST(Geodesy, MeridianConvergenceOfAUtmGridMatchesTheClosedForm) {
  GeoReference geo;
  const std::string utm54 =
      "PROJCS[\"WGS 84 / UTM zone 54N\",GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\","
      "SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],"
      "UNIT[\"degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],"
      "PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",141],"
      "PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],"
      "PARAMETER[\"false_northing\",0],UNIT[\"metre\",1]]";
  geo.crs_wkt = utm54;
  const auto centre = from_lonlat(utm54, 137.5, 36.3);
  geo.geotransform = {centre[0] - 5.0, 10.0, 0.0, centre[1] + 5.0, 0.0, -10.0};
  const double expected = (141.0 - 137.5) * std::sin(radians(36.3));
  EXPECT_NEAR(grid_convergence_deg(geo, 1, 1), expected, 0.02);
}
