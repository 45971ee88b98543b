// Water drains down through the soil and evaporates from its top (issue 33,
// item 3; terrain/soil/drainage.h).
#include "terrain/soil/drainage.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "terrain/soil/scenario.h"
#include "tests/soil/soil_fixtures.h"

namespace drift::soil {
namespace {

// A column of damp sand (`moisture` 0.8: apparent cohesion 0.24 t/m, critical
// height 0.85 m) `height` m tall on 0.1 m voxels, drained at `drainage` m/s
// (K_s) and evaporated at `evaporation` m/s, run `seconds`.
SoilSimulation damp_column(double drainage, double evaporation, double seconds,
                           double moisture = 0.8, double height = 1.0) {
  SoilScenario sc;
  sc.name = "damp_column";
  sc.shape = {32, 32, static_cast<int>(std::lround(height * 10)) + 4, 0.1, {0, 0, 0}};
  sc.options.dt = 1.0 / 30;
  sc.options.soil = soil_preset("dry_sand");
  sc.options.soil.drainage = drainage;
  sc.options.soil.evaporation = evaporation;
  const Primitive column{PrimitiveKind::Cylinder, {0, 0, 0.5 * height}, {0.35, 0, 0.5 * height}};
  sc.soil.push_back({"damp", {column}, {1.6, 1.6, 0}, false, moisture});
  SoilSimulation sim = make_simulation(sc);
  sim.run(static_cast<int>(std::lround(seconds / sc.options.dt)));
  return sim;
}

// Mass-weighted moisture of the centre column's voxels in [z0, z1).
double column_moisture(const SoilState& s, int z0, int z1) {
  const std::size_t c = s.shape.column(s.shape.nx / 2, s.shape.ny / 2);
  double soil = 0, water = 0;
  for (int z = z0; z < z1; ++z) {
    soil += s.rho[c + z];
    water += static_cast<double>(s.rho[c + z]) * s.wet[c + z];
  }
  return soil > 0 ? water / soil : 0;
}

// Drainage only moves water: over 20 s of a fast-draining column (K_s 1 m/s,
// clean gravel's order, Freeze & Cherry 1979, table 2.2, so that the test
// sees the effect in seconds) the water is conserved, moisture stays in
// [0, 1], and it has moved down: the top drier, the foot wetter.
TEST(SoilDrainage, WaterOnlyMovesDownWithoutEvaporation) {
  const SoilSimulation still = damp_column(0.0, 0.0, 0.0);
  const double w0 = still.state().water();
  const SoilSimulation sim = damp_column(1.0, 0.0, 20.0);
  const SoilState& s = sim.state();
  EXPECT_NEAR(s.water() / w0, 1.0, 1e-5);
  const auto [lo, hi] = std::minmax_element(s.wet.begin(), s.wet.end());
  EXPECT_GE(*lo, 0.0f);
  EXPECT_LE(*hi, 1.0f);
  const double foot = column_moisture(s, 0, 2);
  const int top = static_cast<int>(fixtures::column_top_of(s, 16, 16));
  const double upper = column_moisture(s, std::max(0, top - 2), top + 1);
  std::printf("after 20 s: foot %.3f, top %.3f (started 0.8)\n", foot, upper);
  EXPECT_GT(foot, 0.9);
  EXPECT_LT(upper, 0.7);
}

// Evaporation takes E dt / (h theta_s) of water a step from each exposed top
// voxel: a flat damp layer that cannot drain loses exactly its columns
// times that.
TEST(SoilDrainage, EvaporationTakesItsRateFromTheTop) {
  SoilState s({8, 8, 4, 0.1, {0, 0, 0}});
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int z = 0; z < 2; ++z) {
        s.rho[s.shape.index(x, y, z)] = 1.0f;
        s.wet[s.shape.index(x, y, z)] = 0.5f;
      }
  SoilType soil = soil_preset("loam");
  soil.drainage = 0;
  soil.evaporation = 1e-4;
  const double w0 = s.water(), dt = 0.1;
  for (int i = 0; i < 100; ++i) drain_moisture(s, soil, dt);
  const double expected = 64 * 100 * soil.evaporation * dt / (0.1 * soil.porosity);
  EXPECT_NEAR(w0 - s.water(), expected, 1e-4 * expected);
  EXPECT_FLOAT_EQ(s.wet[s.shape.index(3, 3, 0)], 0.5f);  // the covered voxel keeps its water
}

// A wetted heap loses its cohesion near its top as the water drains: a damp
// 2 m column (moisture 0.8) slumps to 1.64 m when its water stays and lower
// (1.49 m) when its upper part drains (a pile's cohesion is that of its
// upper third; with the whole pile's mean moisture the two stood alike,
// since drainage keeps a pile's water).
TEST(SoilDrainage, DrainedHeapLosesCohesionAtItsTop) {
  const SoilSimulation kept = damp_column(0.0, 0.0, 20.0, 0.8, 2.0);
  const SoilSimulation drained = damp_column(1.0, 0.0, 20.0, 0.8, 2.0);
  const float h_kept = fixtures::pile_tops(kept.state()).peak * 0.1f;
  const float h_drained = fixtures::pile_tops(drained.state()).peak * 0.1f;
  std::printf("damp 2 m column after 20 s: water kept %.2f m, drained %.2f m\n", h_kept, h_drained);
  EXPECT_LT(h_drained, h_kept - 0.08f);
}

// The passes added for issue 33's items 3 and 4 (drainage, evaporation,
// riding) give the same bits on 1 and 2 threads: damp soil draining on a
// turning disc, rho and moisture compared bit for bit.
TEST(SoilDrainage, DrainingSoilOnATurningDiscIsTheSameOnOneAndTwoThreads) {
  std::vector<float> first_rho, first_wet;
  for (int threads : {1, 2}) {
    std::vector<float> rho, wet;
    tbb::task_arena arena(threads);
    arena.execute([&] {
      SoilScenario sc;
      sc.name = "damp_disc";
      sc.shape = {32, 32, 14, 0.1, {0, 0, 0}};
      sc.options.soil = soil_preset("sandy_loam");
      sc.options.soil.drainage = 1.0;
      sc.options.soil.evaporation = 1e-4;
      RigidObject disc;
      disc.name = "disc";
      disc.primitives = {{PrimitiveKind::Cylinder, {0, 0, 0}, {1.2, 0, 0.15}}};
      disc.path = {{0.0, {1.6, 1.6, 0.35}}};
      disc.spin = {0, 0, 0.8};
      sc.bodies.push_back(disc);
      sc.soil.push_back({"damp",
                         {{PrimitiveKind::Cuboid, {2.2, 1.6, 0.8}, {0.25, 0.25, 0.3}}},
                         {0, 0, 0},
                         false,
                         0.9});
      SoilSimulation sim = make_simulation(sc);
      sim.run(90);
      rho = sim.state().rho;
      wet = sim.state().wet;
    });
    if (threads == 1) {
      first_rho = rho;
      first_wet = wet;
      continue;
    }
    ASSERT_EQ(rho.size(), first_rho.size());
    EXPECT_EQ(std::memcmp(rho.data(), first_rho.data(), rho.size() * sizeof(float)), 0);
    EXPECT_EQ(std::memcmp(wet.data(), first_wet.data(), wet.size() * sizeof(float)), 0);
  }
}

}  // namespace
}  // namespace drift::soil
