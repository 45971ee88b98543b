// The shared slope relaxation (terrain/slope_relax.h): a pile collapses to its
// angle of repose in every direction with its volume kept, symmetric, within
// its floor and ceiling.
#include "terrain/slope_relax.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace drift::terrain {
namespace {

constexpr int kN = 61;

Grid<double> pile() {
  Grid<double> h(kN, kN, 0.0);
  h(kN / 2, kN / 2) = 500.0;  // a column of 500 m on 1 m cells
  return h;
}

double sum(const Grid<double>& h) {
  double s = 0;
  for (double v : h.values()) s += v;
  return s;
}

TEST(SlopeRelax, APileSettlesAtItsAngleInEveryDirectionKeepingItsVolume) {
  Grid<double> h = pile();
  const SlopeRule rule{std::tan(30.0 * std::numbers::pi / 180.0), 0.2};
  const SlopeCells cells{{&rule, 1}};
  const SlopeRelaxOptions o{1.0, 1.0, 1e-6, 100000};
  std::vector<int> moved;
  const SlopeRelaxReport r = relax_slopes(h, {kN / 2 * kN + kN / 2}, cells, o, moved);
  EXPECT_TRUE(r.converged) << r.passes << " passes";
  EXPECT_NEAR(sum(h), 500.0, 1e-10);
  EXPECT_LE(max_slope_excess(h, cells, o), 1e-6);
  // It spread in all directions into a cone (radius ~9 m for 500 m3 at 30 degrees).
  EXPECT_GT(h(kN / 2 + 2, kN / 2), 0.0);
  EXPECT_GT(h(kN / 2 + 1, kN / 2 + 1), 0.0);
  EXPECT_GT(h(kN / 2 + 2, kN / 2 + 1), 0.0);
  // Not flatter along the diagonals than along the axes: the steepest flank in
  // each direction stands near the angle (a pile on a 4-neighbour or
  // unit-distance stencil would stand too steep or too flat diagonally).
  double axis = 0, diagonal = 0;
  for (int y = 1; y < kN - 1; ++y)
    for (int x = 1; x < kN - 1; ++x) {
      axis = std::max(axis, h(x, y) - h(x + 1, y));
      diagonal = std::max(diagonal, (h(x, y) - h(x + 1, y + 1)) / std::sqrt(2.0));
    }
  EXPECT_NEAR(axis, rule.tan_repose, 0.1 * rule.tan_repose);
  EXPECT_NEAR(diagonal, rule.tan_repose, 0.1 * rule.tan_repose);
  // Symmetric under flips and the transpose (order-independent passes).
  for (int y = 0; y < kN; ++y)
    for (int x = 0; x < kN; ++x) {
      EXPECT_NEAR(h(x, y), h(kN - 1 - x, y), 1e-12);
      EXPECT_NEAR(h(x, y), h(y, x), 1e-12);
    }
}

TEST(SlopeRelax, CeilingsAndFloorsHold) {
  Grid<double> h = pile();
  Grid<double> ceiling(kN, kN, std::numeric_limits<double>::infinity());
  Grid<double> floor(kN, kN, -std::numeric_limits<double>::infinity());
  ceiling(kN / 2 + 1, kN / 2) = 0.1;  // an object holds this neighbour down
  floor(kN / 2, kN / 2) = 498.0;      // only 2 m of the column may move
  const SlopeRule rule{0.5, 0.2};
  const SlopeCells cells{{&rule, 1}, nullptr, &ceiling, &floor};
  std::vector<int> moved;
  relax_slopes(h, {kN / 2 * kN + kN / 2}, cells, {1.0, 1.0, 1e-6, 100000}, moved);
  EXPECT_LE(h(kN / 2 + 1, kN / 2), 0.1 + 1e-12);
  EXPECT_GE(h(kN / 2, kN / 2), 498.0 - 1e-12);
  EXPECT_NEAR(sum(h), 500.0, 1e-10);
}

TEST(SlopeRelax, NinetyDegreesNeverSlides) {
  Grid<double> h = pile();
  const SlopeRule rule{std::numeric_limits<double>::infinity(), 0.2};
  std::vector<int> moved;
  relax_slopes(h, {kN / 2 * kN + kN / 2}, {{&rule, 1}}, {}, moved);
  EXPECT_EQ(h(kN / 2, kN / 2), 500.0);
  EXPECT_TRUE(moved.empty());
}

}  // namespace
}  // namespace drift::terrain
