// Determinism of marks at any thread count (docs/marks.md, Performance): the
// erosion (terrain/slope_relax) splits a pass over TBB's threads once a list
// of cells is long, and every phase of a pass must be a function of each cell
// alone, so one and two threads give the same bits, and the volume is kept.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>

#include "terrain/marks/marks.h"
#include "tests/marks/shapes.h"

namespace drift::marks {
namespace {

constexpr double kCell = 0.01;
constexpr int kSize = 160;

// A 1.2 m square plate pressed 3 cm into sand over four steps, then dragged
// 8 cells a step and lifted: the plate's contact alone is 14,400 cells, so
// the relaxation's lists pass the size at which a pass is split over threads.
terrain::Grid<double> plate_run(int threads, double* compressed = nullptr) {
  tbb::global_control c(tbb::global_control::max_allowed_parallelism, threads);
  const terrain::HeightField ground = testing::flat(kSize, kCell, 1.0f);
  MarksSimulation sim(ground, testing::only("sand"), {});
  const ObjectShape shape = ObjectShape::of(testing::box(0.6, 0.6, 0.05));
  MarkObject object;
  object.motion = Motion::Sweep;
  const double top = 1.0 + 0.05;
  Pose from{testing::at_cell(sim, 70, 80, top + 0.01), Eigen::Quaterniond::Identity()};
  double lost = sim.move(shape, object, from, from, true).compressed;
  sim.end_step();
  auto go = [&](double col, double z) {
    const Pose to{testing::at_cell(sim, col, 80, z), Eigen::Quaterniond::Identity()};
    lost += sim.move(shape, object, from, to, false).compressed;
    sim.end_step();
    from = to;
  };
  for (int s = 1; s <= 4; ++s) go(70, top - 0.0075 * s);
  for (int s = 1; s <= 2; ++s) go(70 + 8 * s, top - 0.03);
  go(86, top + 0.2);  // lifted: the walls slump
  for (int s = 0; s < 3; ++s) go(86, top + 0.2);
  if (compressed) *compressed = lost;
  return sim.heights();
}

TEST(MarksThreads, OneAndTwoThreadsGiveTheSameBitsAndKeepTheVolume) {
  double compressed = 0.0;
  const terrain::Grid<double> one = plate_run(1, &compressed), two = plate_run(2);
  ASSERT_EQ(one.values().size(), two.values().size());
  std::size_t differ = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < one.values().size(); ++i) {
    const double a = one.values()[i], b = two.values()[i];
    if (std::memcmp(&a, &b, sizeof a) != 0) ++differ;
    worst = std::max(worst, std::abs(a - b));
  }
  EXPECT_EQ(differ, 0u) << "cells that differ between 1 and 2 threads (largest " << worst << " m)";
  // The plate pressed the sand: something moved, and the volume is kept to
  // float precision (less what the steps report compressed away).
  const double before = kSize * kSize * kCell * kCell * 1.0;
  EXPECT_NEAR(testing::volume(one, kCell), before - compressed, 1e-9);
  double lowest = 1.0;
  for (double v : one.values()) lowest = std::min(lowest, v);
  EXPECT_LT(lowest, 1.0 - 0.02) << "the plate left no print";
}

}  // namespace
}  // namespace drift::marks
