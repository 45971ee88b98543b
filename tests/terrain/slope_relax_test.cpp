// The shared slope relaxation (terrain/slope_relax.h): a pile collapses to its
// angle of repose in every direction with its volume kept, symmetric, within
// its floor and ceiling.
#include "terrain/slope_relax.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
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

// The cell lists (relax_slopes: a bitmap a word of 64 cells at a time, only
// the givers with an offer and their neighbours taking) against the tiles
// (relax_slopes_everywhere: every cell of the active tiles and their
// neighbours) on a rough field 150 cells wide (words that carry across, a
// short last word), rough cells, a ceiling and a floor: every cell a seed,
// the same bits, and the seeds' order and repeats change nothing.
TEST(SlopeRelax, CellListsGiveTheTilesBitsWhateverTheSeedsOrder) {
  constexpr int kW = 150, kH = 70;
  Grid<double> h(kW, kH, 0.0), ceiling(kW, kH, std::numeric_limits<double>::infinity());
  Grid<double> floor(kW, kH, -std::numeric_limits<double>::infinity());
  std::uint64_t state = 12345;
  auto next = [&] {  // a small LCG: deterministic on every platform
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) h(x, y) = 3.0 * next() + (x == 64 || x == 127 ? 4.0 : 0.0);
  for (int y = 20; y < 30; ++y)
    for (int x = 60; x < 70; ++x) ceiling(x, y) = 1.0;
  for (int y = 40; y < 45; ++y)
    for (int x = 0; x < 10; ++x) floor(x, y) = 2.0;
  SlopeRule rule{std::tan(35.0 * std::numbers::pi / 180.0), 0.3};
  rule.rough = true;
  const SlopeCells cells{{&rule, 1}, nullptr, &ceiling, &floor};
  SlopeRelaxOptions o{1.0, 1.0, 1e-6, 60, 7};
  Grid<double> tiles = h;
  relax_slopes_everywhere(tiles, cells, o);
  std::vector<int> seeds, moved;
  for (int i = 0; i < kW * kH; ++i) seeds.push_back(i);
  Grid<double> lists = h;
  relax_slopes(lists, seeds, cells, o, moved);
  std::vector<int> shuffled(seeds.rbegin(), seeds.rend());
  shuffled.insert(shuffled.end(), seeds.begin(), seeds.begin() + 500);
  Grid<double> again = h;
  relax_slopes(again, shuffled, cells, o, moved);
  int differ = 0, differ_again = 0;
  for (std::size_t i = 0; i < h.values().size(); ++i) {
    differ += tiles.values()[i] != lists.values()[i];
    differ_again += again.values()[i] != lists.values()[i];
  }
  EXPECT_EQ(differ, 0) << "cells where the lists and the tiles differ";
  EXPECT_EQ(differ_again, 0) << "cells that depend on the seeds' order";
  EXPECT_GT(moved.size(), 1000u);
}

// The same from a few seeds on flat ground: columns standing on the cells
// either side of the bitmap's word boundaries (63 | 64, 127 | 128) and on
// the field's edges, seeded alone, slump as when every cell is active.
TEST(SlopeRelax, SeededCellListsGiveTheTilesBitsAcrossWordBoundaries) {
  constexpr int kW = 150, kH = 40;
  Grid<double> h(kW, kH, 0.0);
  std::vector<int> seeds;
  const int columns[][2] = {{63, 5}, {64, 15}, {127, 25}, {128, 34}, {0, 0}, {149, 39}, {149, 12}};
  for (const auto& c : columns) h(c[0], c[1]) = 6.0, seeds.push_back(c[1] * kW + c[0]);
  const SlopeRule rule{std::tan(30.0 * std::numbers::pi / 180.0), 0.2};
  const SlopeCells cells{{&rule, 1}};
  const SlopeRelaxOptions o{1.0, 1.0, 1e-6, 40};
  Grid<double> tiles = h, lists = h;
  relax_slopes_everywhere(tiles, cells, o);
  std::vector<int> moved;
  relax_slopes(lists, seeds, cells, o, moved);
  int differ = 0;
  for (std::size_t i = 0; i < h.values().size(); ++i)
    differ += tiles.values()[i] != lists.values()[i];
  EXPECT_EQ(differ, 0) << "cells where the seeded lists and the tiles differ";
  EXPECT_NEAR(sum(lists), 6.0 * std::size(columns), 1e-9);
}

}  // namespace
}  // namespace drift::terrain
