// Piles that rest (issue 33; docs/soil.md, Method 6, "Failure in metres" and
// "Coming to rest", decisions where the thesis is silent):
// cohesion and friction act in metres over a pile's real height, so a heap
// settles the same at any voxel size and a column above its critical height
// collapses; piles stop moving; cones are round.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "terrain/soil/scenario.h"
#include "terrain/soil/soil_slice.h"
#include "tests/soil/soil_fixtures.h"

namespace drift::soil {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A column of `radius` x `height` metres on a grid of `voxel` metres sized
// to hold the heap it collapses into.
SoilSimulation metric_column(double radius, double height, double width, double voxel,
                             const SoilOptions& o) {
  const int n = static_cast<int>(std::lround(width / voxel));
  const int nz = static_cast<int>(std::ceil(height / voxel)) + 2;
  return fixtures::column_scene(n, nz, radius / voxel, height / voxel, voxel, o);
}

SoilOptions soil_options(const char* preset, double dt) {
  SoilOptions o;
  o.dt = dt;
  o.soil = soil_preset(preset);
  return o;
}

// Culmann's critical height of a vertical cut, 4 c / gamma tan(45 + phi / 2),
// is where rest_angle reaches 90 degrees; cohesionless soil rests at phi; a
// taller slope rests flatter.
TEST(SoilRest, RestAngleFollowsTheCriticalHeight) {
  const double c = 0.2, phi = 22 * kDeg, gamma = 1.9;
  const double critical = 4 * c / gamma * std::tan(M_PI / 4 + phi / 2);
  EXPECT_NEAR(critical, 0.62, 0.01);
  EXPECT_NEAR(rest_angle(critical * 0.999, c, phi, gamma), M_PI / 2, 1e-3);
  EXPECT_LT(rest_angle(critical * 1.5, c, phi, gamma), 80 * kDeg);
  EXPECT_DOUBLE_EQ(rest_angle(5.0, 0.0, phi, gamma), phi);
  EXPECT_GT(rest_angle(5.0, c, phi, gamma), rest_angle(20.0, c, phi, gamma));
  // The angle found has Li & Moshell's F = 1 on the slope's own wedge and no
  // failure plane just below it.
  for (double height : {1.0, 3.0, 20.0}) {
    const double beta = rest_angle(height, c, phi, gamma);
    EXPECT_FALSE(failure_plane(height, height / std::tan(beta - 1e-3), c, phi, gamma)) << height;
    EXPECT_TRUE(failure_plane(height, height / std::tan(beta + 1e-3), c, phi, gamma)) << height;
  }
}

// The same sandy-loam heap (a 10 m wide, 12 m tall column collapsing) at 0.5,
// 1 and 2 m voxels settles within 3 degrees (before: cohesion checked one
// voxel step at a time gave 50, 58 and 66 degrees for a 20 m heap at 2, 1
// and 0.5 m).
TEST(SoilRest, SameHeapSettlesAlikeAtAnyVoxelSize) {
  std::vector<double> angles;
  for (double voxel : {0.5, 1.0, 2.0}) {
    SoilSimulation sim = metric_column(5.0, 12.0, 32.0, voxel, soil_options("sandy_loam", 0.05));
    fixtures::run_until_settled(sim, 3000);
    angles.push_back(fixtures::pile_angle_deg(sim.state()));
  }
  const auto [lo, hi] = std::minmax_element(angles.begin(), angles.end());
  EXPECT_LT(*hi - *lo, 3.0);
  EXPECT_GT(*lo, 25.0);
  EXPECT_LT(*hi, 50.0);
  std::printf("sandy loam heap at 0.5 / 1 / 2 m voxels: %.1f %.1f %.1f degrees\n", angles[0],
              angles[1], angles[2]);
}

// Steepest flank of a pile: the largest top difference between neighbouring
// columns over their distance, in degrees.
double steepest_flank_deg(const SoilState& s) {
  const auto& g = s.shape;
  double steepest = 0;
  for (int y = 0; y + 1 < g.ny; ++y)
    for (int x = 0; x + 1 < g.nx; ++x) {
      const float t = fixtures::column_top_of(s, x, y);
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}})
        steepest = std::max(steepest, std::abs(t - fixtures::column_top_of(s, x + dx, y + dy)) /
                                          std::hypot(dx, dy));
    }
  return std::atan(steepest) * 180 / M_PI;
}

// A 1.6 m column of sandy loam stands above its critical height (0.62 m):
// it must collapse. Before, its flanks stood at 84-89 degrees at 5 cm voxels.
TEST(SoilRest, SandyLoamColumnAboveItsCriticalHeightCollapses) {
  SoilSimulation sim = metric_column(0.4, 1.6, 4.0, 0.1, soil_options("sandy_loam", 1.0 / 30));
  const float top0 = fixtures::column_top_of(sim.state(), 20, 20);
  fixtures::run_until_settled(sim, 1500);
  const double flank = steepest_flank_deg(sim.state());
  const float top1 = fixtures::column_top_of(sim.state(), 20, 20);
  EXPECT_LT(flank, 72.0);
  EXPECT_LT(top1, 0.9f * top0);
  std::printf("1.6 m sandy loam column: top %.2f -> %.2f m, steepest flank %.1f degrees\n",
              top0 * 0.1, top1 * 0.1, flank);
}

// A dry-sand column collapses into a cone that comes to rest: over 10 s more
// no column's top moves by 1 mm (before, the moved soil halved every 5 s and
// still moved at 50 s: 8.2 mm here), at dry sand's angle, and round: its
// half-height radius varies by under 8 % with direction (1.5 %; 7.3 %
// before issue 33, 6.4 % with 16 directions sliding each on its own slope;
// the 3 % bound is CollapsedColumnRestsRoundAtTwoVoxelSizes's).
TEST(SoilRest, DrySandConeComesToRestRound) {
  const double voxel = 0.1;
  SoilSimulation sim = metric_column(0.6, 2.0, 5.6, voxel, soil_options("dry_sand", 1.0 / 30));
  sim.run(450);  // 15 s
  const auto& g = sim.state().shape;
  std::vector<float> before(g.columns());
  for (int y = 0; y < g.ny; ++y)
    for (int x = 0; x < g.nx; ++x)
      before[static_cast<std::size_t>(y) * g.nx + x] = fixtures::column_top_of(sim.state(), x, y);
  sim.run(300);  // 10 s more
  double moved = 0;
  for (int y = 0; y < g.ny; ++y)
    for (int x = 0; x < g.nx; ++x)
      moved = std::max(moved, voxel * std::abs(fixtures::column_top_of(sim.state(), x, y) -
                                               before[static_cast<std::size_t>(y) * g.nx + x]));
  EXPECT_LT(moved, 1e-3) << "m";
  const double spread = fixtures::radius_spread(sim.state(), 0.5, 32);
  EXPECT_LT(spread, 0.08);
  double sectors = 0;
  const double angle = fixtures::pile_angle_deg(sim.state(), &sectors);
  EXPECT_GE(angle, 28.0);
  EXPECT_LE(angle, 37.0);
  std::printf(
      "dry sand cone: %.1f degrees, moved %.2g m over 10 s, half-height radius spread %.1f %%\n",
      angle, moved, 100 * spread);
}

// A collapsed column rests as a round cone with a round foot (issue 33, item
// 4): the radius at half the peak and at a tenth of it (the foot) varies by
// under 3 % over 32 directions, at 0.1 and 0.07 m voxels, and the soil's mass
// is kept. Before, slices that failed each on their own lattice direction
// left the upper cone squarish: 6.4 % and 4.5 % at 0.1 m, 6.4 % and 5.0 %
// at 0.07 m; now 1.5 / 0.8 % and 1.2 / 0.7 % (docs/soil.md).
TEST(SoilRest, CollapsedColumnRestsRoundAtTwoVoxelSizes) {
  for (double voxel : {0.1, 0.07}) {
    SoilSimulation sim = metric_column(0.6, 2.0, 5.6, voxel, soil_options("dry_sand", 1.0 / 30));
    const double mass = sim.state().mass();
    sim.run(450);  // 15 s
    const double half = fixtures::radius_spread(sim.state(), 0.5, 32);
    const double foot = fixtures::radius_spread(sim.state(), 0.1, 32);
    std::printf("%.2f m voxels: radius spread %.1f %% at half height, %.1f %% at the foot\n", voxel,
                100 * half, 100 * foot);
    EXPECT_LT(half, 0.03) << voxel;
    EXPECT_LT(foot, 0.03) << voxel;
    EXPECT_NEAR(sim.state().mass(), mass, 1e-6 * mass) << voxel;
  }
}

// Cohesive soil rests round too (issue 33, item 4, asked again): a sandy-loam
// and a loam column above their critical heights (0.62 and 0.82 m) and a damp
// dry sand (moisture 0.3, apparent cohesion) collapse into cones whose
// half-height radius varies by under 3 % over 32 directions, like dry
// sand's (1.2-1.6 %), and whose foot is as round. Cohesion keeps the cone's
// top steeper and flat-topped, where a lattice's preferred directions would
// show first.
TEST(SoilRest, CohesiveConesRestRound) {
  struct Case {
    const char* preset;
    double moisture, radius, height, width;
  };
  for (const Case& c : {Case{"sandy_loam", -1, 0.6, 2.0, 5.6}, Case{"loam", -1, 1.0, 4.0, 6.4},
                        Case{"dry_sand", 0.3, 0.6, 2.0, 5.6}}) {
    SoilOptions o = soil_options(c.preset, 1.0 / 30);
    if (c.moisture >= 0) o.soil.moisture = c.moisture;
    SoilSimulation sim = metric_column(c.radius, c.height, c.width, 0.1, o);
    const double mass = sim.state().mass();
    sim.run(450);  // 15 s
    const double half = fixtures::radius_spread(sim.state(), 0.5, 32);
    const double foot = fixtures::radius_spread(sim.state(), 0.1, 32);
    const double peak = fixtures::pile_tops(sim.state()).peak * 0.1;
    std::printf(
        "%s (moisture %.1f): peak %.2f m, radius spread %.1f %% at half height, %.1f %% at the "
        "foot\n",
        c.preset, c.moisture, peak, 100 * half, 100 * foot);
    EXPECT_LT(peak, 0.9 * c.height) << c.preset << ": the column did not collapse";
    EXPECT_LT(half, 0.03) << c.preset;
    EXPECT_LT(foot, 0.03) << c.preset;
    EXPECT_NEAR(sim.state().mass(), mass, 1e-6 * mass) << c.preset;
  }
}

// Soil on ground steeper than its friction angle slides down it and comes to
// rest at the foot (issue 33, item 6): a 1.2 m layer of sandy loam over
// x = 4-16 m of a 45-degree slope of a height-field terrain (1 m voxels, a
// staircase of one-voxel steps; the foot at x = 20 m) gathers in a deposit
// about the foot: its centroid moves from x = 10 to beyond 16 m and under
// 5 % stays above x = 12 m. Before, each step's soil met its lower
// neighbour only through a zero-height edge span, so only its thickness
// counted: centroid 13.3 m, 33 % left as a blanket on the upper slope.
TEST(SoilRest, SoilOnASteepSlopeSlidesToTheFoot) {
  SoilScenario sc;
  sc.name = "slope";
  sc.shape = {40, 8, 30, 1.0, {0, 0, 0}};
  sc.options = soil_options("sandy_loam", 0.05);
  sc.terrain.kind = TerrainSource::Kind::HeightField;
  sc.terrain.heights = terrain::HeightField(40, 8, 0.0f, terrain::local_georeference(1.0));
  for (int row = 0; row < 8; ++row)
    for (int x = 0; x < 40; ++x)
      sc.terrain.heights(x, row) = static_cast<float>(2.0 + std::max(0.0, 20.0 - (x + 0.5)));
  sc.soil.push_back({"layer",
                     {{PrimitiveKind::Cuboid, {0, 0, 0.6}, {6.0, 4.0, 0.6}}},
                     {10.0, 4.0, 0.0},
                     true,
                     std::nullopt});
  SoilSimulation sim = make_simulation(sc);
  const double total = sim.state().mass();
  ASSERT_GT(total, 50.0);
  sim.run(600);  // 30 s
  const SoilState& s = sim.state();
  // Per column x: soil (voxels, summed over y).
  std::vector<double> along(40, 0.0);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 40; ++x)
      for (int z = 0; z < 30; ++z) along[x] += s.rho[s.shape.index(x, y, z)];
  double upper = 0, centre = 0;
  for (int x = 0; x < 40; ++x) {
    if (x < 12) upper += along[x];
    centre += along[x] * (x + 0.5) / total;
    std::printf("%.0f ", along[x]);
  }
  std::printf(
      "\nsoil on a 45 degree slope: centroid x %.1f m (was 10), %.1f %% left above x = 12 m\n",
      centre, 100 * upper / total);
  EXPECT_GT(centre, 16.0);
  EXPECT_LT(upper / total, 0.05);
}

}  // namespace
}  // namespace drift::soil
