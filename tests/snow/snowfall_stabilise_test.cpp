// Stabilisation (paper 003, 2.1(3)): no snow-surface slope above repose where
// snow lies, mass conserved to double rounding, symmetric, thread-count independent.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <numbers>
#include <numeric>

#include "snow/snowfall_mesh_refine.h"
#include "snow/stabilise_grid.h"
#include "snow/stabilise_mesh.h"

namespace {

using drift::snow::max_repose_excess;
using drift::snow::stabilise_grid;
using drift::snow::StabiliseOptions;
using drift::terrain::Grid;

double total(const Grid<double>& g) {
  return std::accumulate(g.values().begin(), g.values().end(), 0.0);
}

TEST(SnowfallStabilise, PileOnFlatGroundSettlesAtReposeConservesMassAndStaysSymmetric) {
  const int n = 41;
  Grid<float> ground(n, n, 0.0f);
  Grid<double> snow(n, n, 0.0);
  snow(20, 20) = 30.0;  // a 30 m column on 1 m cells
  const double before = total(snow);
  StabiliseOptions o;
  const auto r = stabilise_grid(ground, snow, 1.0, 1.0, o);
  EXPECT_TRUE(r.converged) << r.iterations;
  EXPECT_NEAR(total(snow), before, 1e-12 * before);
  EXPECT_LE(max_repose_excess(ground, snow, 1.0, 1.0, o.repose_deg, 0.0), 4 * o.tolerance);
  EXPECT_GT(snow(20, 20), 2.0);  // a cone, not a film
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      EXPECT_GE(snow(x, y), -1e-12);
      EXPECT_NEAR(snow(x, y), snow(n - 1 - x, y), 1e-9) << x << "," << y;
      EXPECT_NEAR(snow(x, y), snow(x, n - 1 - y), 1e-9) << x << "," << y;
    }
}

TEST(SnowfallStabilise, SnowSlidesOffASlopeSteeperThanRepose) {
  // 60-degree ramp down to the east ending in a flat floor; 1 m of snow everywhere.
  const int w = 60, h = 8;
  Grid<float> ground(w, h, 0.0f);
  const double t60 = std::tan(60.0 * std::numbers::pi / 180.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 30; ++x) ground(x, y) = static_cast<float>((30 - x) * 0.5 * t60);
  Grid<double> snow(w, h, 1.0);
  const double before = total(snow);
  StabiliseOptions o;
  stabilise_grid(ground, snow, 0.5, 0.5, o);
  EXPECT_NEAR(total(snow), before, 1e-12 * before);
  // Cells holding less than the tolerance count as bare (it is what can no longer move).
  EXPECT_LE(max_repose_excess(ground, snow, 0.5, 0.5, o.repose_deg, 2 * o.tolerance),
            4 * o.tolerance);
  // The slope keeps at most a thin skin; the floor got what slid.
  EXPECT_LT(snow(10, 4), 0.05);
  EXPECT_GT(snow(31, 4), 1.5);
}

TEST(SnowfallStabilise, UniformSnowOnFlatGroundDoesNotMove) {
  Grid<float> ground(16, 16, 5.0f);
  Grid<double> snow(16, 16, 0.2);
  stabilise_grid(ground, snow, 1.0, 1.0);
  for (double v : snow.values()) EXPECT_EQ(v, 0.2);
}

TEST(SnowfallStabilise, SameBitsForAnyThreadCount) {
  const int n = 150;  // several tiles
  Grid<float> ground(n, n, 0.0f);
  Grid<double> start(n, n, 0.0);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      ground(x, y) = static_cast<float>(8.0 * std::sin(x * 0.21) * std::cos(y * 0.17));
      start(x, y) = 0.5 + 0.4 * std::sin(x * 1.3 + y * 0.7);
    }
  Grid<double> one = start, two = start;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    stabilise_grid(ground, one, 1.0, 1.0);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    stabilise_grid(ground, two, 1.0, 1.0);
  }
  EXPECT_EQ(one.values(), two.values());
}

// A 2 x 1 m plate, tilted by `tilt_deg` about the y axis, refined to 0.1 m edges.
drift::terrain::Mesh plate(double tilt_deg) {
  drift::terrain::Mesh m;
  const double s = std::sin(tilt_deg * std::numbers::pi / 180.0),
               c = std::cos(tilt_deg * std::numbers::pi / 180.0);
  for (auto [x, y] : {std::pair{-1.0, -0.5}, {1.0, -0.5}, {1.0, 0.5}, {-1.0, 0.5}})
    m.positions.emplace_back(static_cast<float>(x * c), static_cast<float>(y),
                             static_cast<float>(2.0 - x * s));
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return drift::snow::refine_mesh(m, 0.1);
}

TEST(SnowfallStabilise, MeshKeepsSnowOnAFlatPlateAndSheddsItFromASteepOne) {
  for (double tilt : {0.0, 60.0}) {
    const auto m = plate(tilt);
    const auto a = drift::snow::vertex_footprints(m);
    std::vector<double> volume(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) volume[i] = a[i] * 0.05;  // 5 cm everywhere
    const double before = std::accumulate(volume.begin(), volume.end(), 0.0);
    const auto r = drift::snow::stabilise_mesh(m, a, volume);
    const double kept = std::accumulate(volume.begin(), volume.end(), 0.0);
    const double shed = std::accumulate(r.shed.begin(), r.shed.end(), 0.0);
    EXPECT_TRUE(r.converged);
    EXPECT_NEAR(kept + shed, before, 1e-12 * before) << tilt;
    if (tilt == 0.0) {
      EXPECT_GT(kept, 0.9 * before);  // only the rim can lose a little
    } else {
      EXPECT_LT(kept, 0.05 * before);  // 60 degrees > 40: it slides off the low edge
    }
  }
}

}  // namespace
