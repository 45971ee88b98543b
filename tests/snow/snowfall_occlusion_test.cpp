// Occlusion (paper 003, 2.1(1)-(2)): no snow under a roof for a vertical fall,
// partial snow near its edge with spread, exactly rate x time on open flat
// ground, the horizon sweep agrees with the OSMesa depth map, no acne at grazing
// light, same bits for any thread count.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "snow/snowfall.h"
#include "snow/snowfall_directions.h"
#include "terrain/error.h"
#include "terrain/mesh_io.h"
#include "terrain/products.h"

namespace {

using namespace drift::snow;
using drift::terrain::HeightField;

// 14 x 14 m of flat ground at 2000 m, 0.25 m cells, the hut in the middle.
HeightField flat_ground() {
  HeightField g(56, 56, 2000.0f, drift::terrain::local_georeference(0.25));
  g.geo().geotransform[0] = 500000.0;
  g.geo().geotransform[3] = 4000000.0;
  return g;
}

std::vector<drift::terrain::PlacedMesh> hut(const HeightField& g) {
  const auto c = g.geo().cell_center(27.5, 27.5);
  drift::terrain::PlacedMesh placed;
  placed.mesh = drift::terrain::read_obj(DRIFT_SOURCE_DIR "/data/objects/hut.obj");
  placed.position = Eigen::Vector3d(c[0], c[1], 2000.0);
  return {placed};
}

// Cell of CRS point (x, y) (hut frame: metres from the hut's centre).
std::pair<int, int> cell(double x, double y) {
  return {static_cast<int>(27.5 + x / 0.25 + 0.5), static_cast<int>(27.5 - y / 0.25 + 0.5)};
}

TEST(SnowfallOcclusion, VerticalFallReachesNothingUnderTheRoof) {
  const HeightField g = flat_ground();
  const SnowScene scene = make_snow_scene(g, hut(g), 0.25);
  const auto p = snow_probability(scene, jittered_directions(0.0, 90.0, 0.0, 1, 1)).ground;
  // The roof overhangs the 4 x 3 m walls by 0.5 m at the gables and 0.7 m at the eaves.
  for (auto [x, y] : {std::pair{2.25, 0.0}, {-2.25, 0.5}, {0.0, 1.9}, {1.0, -1.9}, {0.0, 0.0}}) {
    const auto [c, row] = cell(x, y);
    EXPECT_EQ(p(c, row), 0.0f) << "under the roof at " << x << ", " << y;
  }
  for (auto [x, y] : {std::pair{2.75, 0.0}, {0.0, 2.5}, {-6.0, -6.0}}) {
    const auto [c, row] = cell(x, y);
    EXPECT_EQ(p(c, row), 1.0f) << "open ground at " << x << ", " << y;
  }
}

TEST(SnowfallOcclusion, OpenFlatGroundGetsExactlyRateTimesHoursAndMassAddsUp) {
  const HeightField g = flat_ground();
  SnowfallOptions o;
  o.spread_deg = 0.0;
  o.maps = 1;
  o.rate_m_per_h = 0.03;
  o.hours = 7.0;
  const auto r = simulate_snowfall(g, hut(g), o);
  const float expected = static_cast<float>(0.03 * 7.0);
  for (auto [x, y] : {std::pair{-6.0, -6.0}, {6.0, 0.0}, {0.0, 5.0}, {-5.0, 6.0}}) {
    const auto [c, row] = cell(x, y);
    EXPECT_EQ(r.depth(c, row), expected) << "open ground at " << x << ", " << y;
  }
  // Under the middle of the roof, far from every drip line, no snow.
  const auto [cm, rm] = cell(0.0, 0.0);
  EXPECT_EQ(r.depth(cm, rm), 0.0f);
  // The 30-degree roof (below the 40-degree repose) keeps most of its snow:
  // 5 x 4.4 m of roof plan, 0.21 m fallen.
  EXPECT_GT(r.object_volume, 0.7 * 5.0 * 4.4 * 0.21);
  EXPECT_NEAR(r.ground_volume + r.object_volume + r.lost_volume, r.fallen_volume,
              1e-9 * r.fallen_volume);
}

TEST(SnowfallOcclusion, SnowyObjectsHaveTheDeclaredFormInItsOrder) {
  // The writer of the snowy objects and their reader ([snow] objects) meet in
  // terrain::products::kSnowyObjects: the mesh carries exactly its attributes.
  const HeightField g = flat_ground();
  SnowfallOptions o;
  o.spread_deg = 0.0;
  o.maps = 1;
  const auto r = simulate_snowfall(g, hut(g), o);
  const auto& form = drift::terrain::products::kSnowyObjects;
  ASSERT_EQ(r.objects.vertex_attributes.size(), form.attributes.size());
  for (std::size_t a = 0; a < form.attributes.size(); ++a)
    EXPECT_EQ(r.objects.vertex_attributes[a].first, form.attributes[a]);
  EXPECT_EQ(drift::terrain::products::split_objects(r.objects, form, "hut.ply").size(), 1u);
}

TEST(SnowfallOcclusion, SpreadGivesPartialSnowAtTheRoofEdgeAndNoneDeepUnder) {
  const HeightField g = flat_ground();
  SnowfallOptions o;
  o.spread_deg = 12.0;
  o.maps = 16;
  o.mesh_max_edge = 0.0;  // faster; the ground is what is tested
  const auto r = simulate_snowfall(g, hut(g), o);
  const float full = static_cast<float>(o.rate_m_per_h * o.hours);
  // Just inside the eave line (the roof edge is at y = 2.2) snow blows in partly.
  const auto [ce, re] = cell(0.0, 2.05);
  EXPECT_GT(r.depth(ce, re), 0.02f * full);
  EXPECT_LT(r.depth(ce, re), 0.98f * full);
  // Close to the wall, under 0.7 m of roof 2.2 m up, a 12-degree spread hardly reaches.
  const auto [cw, rw] = cell(0.0, 1.55);
  EXPECT_LT(r.depth(cw, rw), 0.1f * full);
}

TEST(SnowfallOcclusion, HorizonSweepAgreesWithTheOsmesaDepthMap) {
  // A ridge and a cone on a plane, 1 m cells, snow from the south-west at 35 degrees.
  const int n = 96;
  HeightField g(n, n, 0.0f, drift::terrain::local_georeference(1.0));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double r = std::hypot(x - 60.0, y - 40.0);
      g(x, y) = static_cast<float>(std::max(0.0, 25.0 - 0.9 * r) +
                                   12.0 * std::exp(-std::pow((x + 0.4 * y - 40.0) / 6.0, 2)));
    }
  const SnowScene scene = make_snow_scene(g, {}, 0.0);
  const auto dirs = jittered_directions(225.0, 35.0, 0.0, 1, 1);
  ProbabilityOptions sweep, gl;
  gl.terrain = TerrainOcclusion::OpenGL;
  const auto a = snow_probability(scene, dirs, sweep).ground;
  const auto b = snow_probability(scene, dirs, gl).ground;
  int differ = 0, differ_inside = 0, shadowed = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      shadowed += a(x, y) == 0.0f;
      if (a(x, y) == b(x, y)) continue;
      ++differ;
      // A disagreement must sit on a shadow boundary (within 2 cells of a change in the sweep).
      bool boundary = false;
      for (int j = std::max(y - 2, 0); j <= std::min(y + 2, n - 1); ++j)
        for (int i = std::max(x - 2, 0); i <= std::min(x + 2, n - 1); ++i)
          boundary = boundary || a(i, j) != a(x, y);
      differ_inside += !boundary;
    }
  EXPECT_GT(shadowed, n * n / 20);  // the test has shadows to agree on
  // The shadow edges may shift by a cell (texel-sized depth-map edges, the sweep's
  // interpolation between cells); nowhere else may they disagree.
  EXPECT_LT(differ, n * n * 3 / 100) << differ << " of " << n * n << " cells differ";
  EXPECT_LE(differ_inside, n * n / 1000) << differ_inside << " disagreements off boundaries";
}

TEST(SnowfallOcclusion, NoAcneOnAPlaneLitAtAGrazingAngle) {
  // A plane rising 30 degrees to the north, snow from the south at 35 degrees
  // elevation: 85 degrees between the plane's normal and the source. Nothing shades it.
  const int n = 64;
  HeightField g(n, n, 0.0f, drift::terrain::local_georeference(0.5));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) g(x, y) = static_cast<float>((n - 1 - y) * 0.5 * std::tan(0.5236));
  const SnowScene scene = make_snow_scene(g, {}, 0.0);
  ProbabilityOptions gl;
  gl.terrain = TerrainOcclusion::OpenGL;
  for (double el : {35.0, 60.0}) {
    const auto p = snow_probability(scene, jittered_directions(0.0, el, 0.0, 1, 1), gl).ground;
    for (float v : p.values()) ASSERT_EQ(v, 1.0f) << "elevation " << el;
  }
}

TEST(SnowfallOcclusion, SameBitsForAnyThreadCount) {
  const HeightField g = flat_ground();
  SnowfallOptions o;
  o.maps = 4;
  o.spread_deg = 10.0;
  SnowfallResult one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = simulate_snowfall(g, hut(g), o);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = simulate_snowfall(g, hut(g), o);
  }
  EXPECT_EQ(one.depth.values(), two.depth.values());
  EXPECT_EQ(one.coverage.values(), two.coverage.values());
  EXPECT_EQ(one.objects.positions, two.objects.positions);
}

TEST(SnowfallOcclusion, JitteredDirectionsAreDeterministicAndWeighted) {
  const auto a = jittered_directions(300.0, 60.0, 8.0, 16, 7);
  const auto b = jittered_directions(300.0, 60.0, 8.0, 16, 7);
  const auto c = jittered_directions(300.0, 60.0, 8.0, 16, 8);
  float sum = 0.0f;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].toward_source, b[k].toward_source);
    EXPECT_LE(a[k].angle_rad, 2.5 * 8.0 * M_PI / 180.0 + 1e-12);
    sum += a[k].weight;
  }
  EXPECT_NEAR(sum, 1.0f, 1e-6f);
  EXPECT_NE(a[0].toward_source, c[0].toward_source);
  EXPECT_THROW(jittered_directions(0.0, 10.0, 5.0, 8, 1), drift::Error);  // dips below 1 degree
}

}  // namespace
