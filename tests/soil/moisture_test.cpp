// Moisture as a per-voxel field carried with the soil (issue 33, item 2's
// rest; thesis 5.3.4): water is conserved as the soil moves, a wet region
// stands steeper than a dry one in the same run, and the wetness goes where
// the soil goes, into the mesh's wetness and the VDB's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "terrain/products.h"
#include "terrain/soil/scenario.h"
#include "terrain/soil/soil_surface.h"
#include "tests/soil/soil_fixtures.h"

namespace drift::soil {
namespace {

// Water (sum of rho m) and moisture in [0, 1] over a push and a pour whose
// soil starts with moisture varying along x: every pass that moves soil
// (force propagation, advection, overflow, settle, slippage) must move its
// water with it. Relative drift below 1e-5 (float sums over 300 steps; the
// mass's own bound is 1e-6).
TEST(SoilMoisture, WaterIsConservedOverARun) {
  for (SoilScenario sc : {fixtures::push_scenario(32), fixtures::pour_block_scenario(32)}) {
    SoilSimulation sim = make_simulation(sc);
    SoilState& s = sim.state();
    const auto& g = s.shape;
    for (int y = 0; y < g.ny; ++y)
      for (int x = 0; x < g.nx; ++x)
        for (int z = 0; z < g.nz; ++z) s.wet[g.index(x, y, z)] = (x % 8) / 7.0f;
    const double w0 = s.water(), m0 = s.mass();
    ASSERT_GT(w0, 0.1 * m0);
    for (int step = 0; step < 300; ++step) {
      sim.step();
      if (step % 50) continue;
      const auto [lo, hi] = std::minmax_element(s.wet.begin(), s.wet.end());
      ASSERT_GE(*lo, 0.0f) << sc.name << " step " << step;
      ASSERT_LE(*hi, 1.0f) << sc.name << " step " << step;
    }
    EXPECT_NEAR(s.water() / w0, 1.0, 1e-5) << sc.name << ": " << w0 << " -> " << s.water();
    EXPECT_NEAR(s.mass() / m0, 1.0, 1e-6) << sc.name;
    std::printf("%s: water %.7g -> %.7g (relative %.2g)\n", sc.name.c_str(), w0, s.water(),
                s.water() / w0 - 1);
  }
}

// Top of the highest column within [x0, x1) (voxels).
float peak_between(const SoilState& s, int x0, int x1) {
  float peak = 0;
  for (int y = 0; y < s.shape.ny; ++y)
    for (int x = x0; x < x1; ++x) peak = std::max(peak, fixtures::column_top_of(s, x, y));
  return peak;
}

// Two equal 1 m columns of dry sand in one grid, one damp (moisture 0.8:
// apparent cohesion 0.24 t/m, critical height 0.85 m), one dry: the dry one
// slumps to a 30 degree cone, the damp one keeps more of its height. Each
// pile's cohesion comes from its own moisture, not the scenario's.
TEST(SoilMoisture, WetRegionStandsSteeperThanDryInTheSameRun) {
  SoilScenario sc;
  sc.name = "wet_and_dry";
  sc.shape = {64, 32, 14, 0.1, {0, 0, 0}};
  sc.options.dt = 1.0 / 30;
  sc.options.soil = soil_preset("dry_sand");
  const Primitive column{PrimitiveKind::Cylinder, {0, 0, 0.5}, {0.35, 0, 0.5}};
  sc.soil.push_back({"dry", {column}, {1.6, 1.6, 0}, false, {}});
  sc.soil.push_back({"damp", {column}, {4.8, 1.6, 0}, false, 0.8});
  SoilSimulation sim = make_simulation(sc);
  fixtures::run_until_settled(sim, 1500);
  const SoilState& s = sim.state();
  const float dry = peak_between(s, 0, 32) * 0.1f, damp = peak_between(s, 32, 64) * 0.1f;
  std::printf("1 m columns after settling: dry %.2f m, damp %.2f m\n", dry, damp);
  EXPECT_LT(dry, 0.75f);  // a dry column of this size slumps
  EXPECT_GT(damp, dry + 0.15f);
}

// Wet soil pushed by the blade into dry soil: the heap ahead of the blade
// holds the wet soil's water, and the mesh's wetness there says so.
TEST(SoilMoisture, WetnessFollowsTheSoilThatMoved) {
  SoilScenario sc = fixtures::push_scenario(32);
  SoilSimulation sim = make_simulation(sc);
  SoilState& s = sim.state();
  const auto& g = s.shape;
  // Wet where the blade starts (x < 10 voxels), dry beyond.
  auto water_beyond = [&](int x0) {
    double w = 0;
    for (int y = 0; y < g.ny; ++y)
      for (int x = x0; x < g.nx; ++x)
        for (int z = 0; z < g.nz; ++z) {
          const std::size_t i = g.index(x, y, z);
          w += static_cast<double>(s.rho[i]) * s.wet[i];
        }
    return w;
  };
  for (int y = 0; y < g.ny; ++y)
    for (int x = 0; x < 10; ++x)
      for (int z = 0; z < g.nz; ++z) s.wet[g.index(x, y, z)] = 1.0f;
  ASSERT_EQ(water_beyond(10), 0.0);
  const double w0 = s.water();
  sim.run(300);  // the blade travels from x = 3 to x = 22 voxels
  // It cuts the layer's top 2.6 voxels over 19 voxels of width: about 250
  // voxels of wet soil lay ahead of it in the strip, and most must now lie
  // beyond it (253 measured; 0 if the moisture stays where it was).
  const double moved = water_beyond(10);
  std::printf("water beyond the wet strip: %.4g of %.4g voxels\n", moved, w0);
  EXPECT_GT(moved, 150.0);
  EXPECT_NEAR(s.water() / w0, 1.0, 1e-5);
  // The mesh: vertices of the heap beyond the strip are wet (wet soil mixed
  // with the dry it pushed), those of the untouched layer beside the blade's
  // path beyond the strip dry.
  const terrain::Mesh mesh = soil_surface(s, {});
  const auto& wet = mesh.vertex_attributes.back();
  ASSERT_EQ(wet.first, terrain::products::kWetness);
  double heap = 0, side = 0;
  int heap_n = 0, side_n = 0;
  const float layer_top = 0.25f * 32 * 0.1f;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Eigen::Vector3f& p = mesh.positions[v];
    if (p.x() > 1.2f && p.z() > layer_top + 0.15f) heap += wet.second[v], ++heap_n;
    if (p.x() > 1.5f && p.y() < 0.4f && std::abs(p.z() - layer_top) < 0.05f)
      side += wet.second[v], ++side_n;
  }
  ASSERT_GT(heap_n, 0);
  ASSERT_GT(side_n, 0);
  std::printf("mesh wetness: heap %.2f (%d vertices), dry layer %.2f (%d)\n", heap / heap_n, heap_n,
              side / side_n, side_n);
  EXPECT_GT(heap / heap_n, 0.1);
  EXPECT_LT(side / side_n, 0.25 * heap / heap_n);  // 0.02: windrows spill a little wet soil
}

// The field at a point is the soil-weighted moisture around it.
TEST(SoilMoisture, MoistureAtWeighsTheSoilNotTheAir) {
  SoilState s({4, 4, 4, 1.0, {0, 0, 0}});
  const std::size_t full = s.shape.index(1, 1, 1), empty = s.shape.index(1, 1, 2);
  s.rho[full] = 1.0f;
  s.wet[full] = 0.6f;
  s.wet[empty] = 1.0f;  // no soil: its moisture means nothing
  EXPECT_NEAR(moisture_at(s, {1.5f, 1.5f, 2.0f}), 0.6f, 1e-6f);
  EXPECT_EQ(moisture_at(s, {3.9f, 3.9f, 3.9f}), 0.0f);
}

}  // namespace
}  // namespace drift::soil
