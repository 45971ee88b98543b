// The vectorised kernels of a sand step against their plain definitions:
// one avalanche sweep against the 8-neighbour sum cell by cell, the wind
// shadow along rows against the shadow line cast by every sample upwind, the
// height range against std::minmax_element, and the AVX2 compilations
// against the baseline ones, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

#include "dunes/avalanche.h"
#include "dunes/height_range.h"
#include "dunes/sand_model.h"
#include "dunes/wind_shadow.h"
#include "terrain/simd.h"

using namespace drift::dunes;
using drift::terrain::HeightField;

namespace {

// Uniform heights in [lo, hi) with a few tall spikes, on purpose at the
// wrapped edges and corners too.
HeightField spiky_field(int w, int h, float lo, float hi, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  HeightField f(w, h);
  for (float& v : f.values()) v = u(rng);
  for (auto [x, y] : {std::pair{0, 0}, {w - 1, 0}, {0, h - 1}, {w - 1, h - 1}, {w / 2, h / 3}}) {
    f(x, y) += 40.0f;
  }
  return f;
}

// The height of the neighbour (dx, dy) of (x, y) on a wind lattice of
// shift S: past the last row, row 0 goes on S columns back, so point
// (x, y + rows) is (x - S, y).
float neighbour(const HeightField& h, int x, int y, int dx, int dy, int shift) {
  const int w = h.width(), rows = h.height();
  const int laps = y + dy < 0 ? -1 : (y + dy >= rows ? 1 : 0);
  return h(((x + dx - laps * shift) % w + w) % w, y + dy - laps * rows);
}

// One Jacobi sweep as the avalanche's doc defines it: every cell sums, over
// its 8 neighbours in the order W, E, N, S, NW, NE, SW, SE, the excess drop
// across each edge, whose limit is `limit` times the edge's length (sqrt 2
// on diagonals), and loses a ninth of the sum.
HeightField reference_sweep(const HeightField& h, float limit, int shift) {
  auto edge_limit = [&](int dx, int dy) {
    return static_cast<float>(limit * std::sqrt(static_cast<double>(dx * dx + dy * dy)));
  };
  auto excess = [](float a, float b, float lim) {
    const float d = a - b;
    return std::max(d - lim, 0.0f) + std::min(d + lim, 0.0f);
  };
  const int w = h.width(), rows = h.height();
  HeightField out(w, rows);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < w; ++x) {
      auto edge = [&](int dx, int dy) {
        return excess(h(x, y), neighbour(h, x, y, dx, dy, shift), edge_limit(dx, dy));
      };
      const float axis = edge(-1, 0) + edge(1, 0) + edge(0, -1) + edge(0, 1);
      const float diag = edge(-1, -1) + edge(1, -1) + edge(-1, 1) + edge(1, 1);
      out(x, y) = h(x, y) - (axis + diag) * (1.0f / 9.0f);
    }
  }
  return out;
}

// Sizes whose rows are cut into several strips (dunes/sweep_tiles.h) and rows
// into blocks with a short last one, with wrapped columns: the grid, and
// wind lattices whose rows wrap shifted.
const std::pair<int, int> kSweepSizes[] = {{37, 23}, {64, 64}, {9, 40}, {2100, 19}, {1030, 3}};

}  // namespace

TEST(Kernels, AvalancheSweepsAreTheEightNeighbourSum) {
  for (auto [w, h] : kSweepSizes) {
    for (const int shift : {0, 5, w / 2, w - 1}) {
      const float limit = 0.7f;
      HeightField fast = spiky_field(w, h, 0.0f, 3.0f, 7);
      HeightField slow = fast;
      for (int sweep = 0; sweep < 5; ++sweep) {
        avalanche(fast, limit, 1, -1.0, shift);
        slow = reference_sweep(slow, limit, shift);
        ASSERT_EQ(fast.values(), slow.values())
            << w << "x" << h << ", shift " << shift << ", sweep " << sweep;
      }
    }
  }
}

TEST(Kernels, CreepIsTheFourNeighbourSumAndTheSteepestEdgeIsFound) {
  for (auto [w, h] : kSweepSizes) {
    for (const int shift : {0, 5, w - 1}) {
      const HeightField start = spiky_field(w, h, 0.0f, 3.0f, 11);
      HeightField crept = start;
      const float d = 0.3f;
      creep(crept, d, shift);
      float steepest = 0.0f;
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const float c = start(x, y);
          auto at = [&](int dx, int dy) { return neighbour(start, x, y, dx, dy, shift); };
          const float expected =
              c + d / 4 * ((at(-1, 0) - c) + (at(1, 0) - c) + (at(0, -1) - c) + (at(0, 1) - c));
          ASSERT_EQ(crept(x, y), expected) << w << "x" << h << " at " << x << "," << y;
          for (const auto& [dx, dy] : {std::pair{1, 0}, {0, 1}, {1, 1}, {-1, 1}}) {
            const float lim =
                dx != 0 && dy != 0 ? static_cast<float>(std::numbers::sqrt2 * 0.7) : 0.7f;
            steepest = std::max(steepest, std::fabs(c - at(dx, dy)) - lim);
          }
        }
      }
      EXPECT_EQ(max_excess(start, 0.7, shift), steepest) << w << "x" << h << ", shift " << shift;
    }
  }
}

TEST(Kernels, TheShadowAlongRowsIsCastByEverySampleUpwind) {
  // Heights and drop in halves: every shadow line height is exact, so the
  // definition can be evaluated directly. A sample is shadowed if some
  // sample k columns upwind (periodic) stands more than k drops above it.
  const int w = 48, rows = 11;
  const double drop = 0.5;
  std::mt19937 rng(3);
  HeightField h(w, rows);
  for (float& v : h.values()) v = 0.5f * static_cast<float>(rng() % 24);
  ShadowMap shadow;
  const int max_columns = 9;
  wind_shadow(h, height_range(h), drop, max_columns, shadow);
  for (int row = 0; row < rows; ++row) {
    std::vector<bool> expected(w, false);
    for (int x = 0; x < w; ++x) {
      for (int k = 1; k < w; ++k) {
        if (h((x - k + w) % w, row) - k * drop > h(x, row)) expected[x] = true;
      }
    }
    for (int x = 0; x < w; ++x) {
      const std::uint16_t s = shadow[static_cast<std::size_t>(row) * w + x];
      ASSERT_EQ(shadowed(s), expected[x]) << "row " << row << ", column " << x;
      // Columns to the first shadowed sample downwind, at most the longest
      // flight plus one.
      int reach = 1;
      while (reach < max_columns + 1 && !expected[(x + reach) % w]) ++reach;
      EXPECT_EQ(columns_to_shadow(s), reach) << "row " << row << ", column " << x;
    }
  }
}

TEST(Kernels, HeightRangeIsTheSmallestAndLargestValue) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-50.0f, 50.0f);
  for (auto [w, h] : {std::pair{1, 1}, {3, 5}, {17, 9}, {300, 301}}) {
    HeightField f(w, h);
    for (float& v : f.values()) v = u(rng);
    const auto [lo, hi] = std::minmax_element(f.values().begin(), f.values().end());
    const HeightRange r = height_range(f);
    EXPECT_EQ(r.lo, *lo) << w << "x" << h;
    EXPECT_EQ(r.hi, *hi) << w << "x" << h;
  }
}

TEST(Kernels, TheAvx2TwinsGiveTheBaselineBits) {
  if (drift::simd::active() != drift::simd::Isa::Avx2) {
    GTEST_SKIP() << "this CPU has no AVX2 (or DRIFT_SIMD=sse2): one compilation runs";
  }
  for (double wind : {270.0, 300.0}) {
    for (Model model : {Model::Dunes, Model::Ripples}) {
      SandOptions o = default_options(model);
      o.size = 72;
      o.steps = 80;
      o.wind_from_deg = wind;
      const HeightField wide = run(o);
      HeightField baseline;
      {
        const drift::simd::Limit sse2(drift::simd::Isa::Sse2);
        ASSERT_EQ(drift::simd::active(), drift::simd::Isa::Sse2);
        baseline = run(o);
      }
      EXPECT_EQ(drift::simd::active(), drift::simd::Isa::Avx2);
      EXPECT_EQ(wide.values(), baseline.values())
          << "wind " << wind << ", model " << static_cast<int>(model);
    }
  }
}

TEST(Kernels, TheLiftRecoversLinearlyOverTheShadowsLengthTimesTheRatio) {
  // One line of 40 samples: a shadow over columns 10-13 (4 long), another
  // over 36-39 running on into 0-1 across the periodic edge (6 long), and a
  // line without shadow. Ratio 1.5: ramps of 6 and 9 samples.
  const int n = 40;
  ShadowMap shadow(2 * n, std::uint16_t{2});  // unshadowed, reach 1
  auto shade = [&](int x) { shadow[x] |= 1u; };
  for (int x = 10; x <= 13; ++x) shade(x);
  for (int x : {36, 37, 38, 39, 0, 1}) shade(x);
  std::vector<float> recovery;
  shadow_recovery(shadow, n, 1.5, recovery);
  for (int x = 0; x < n; ++x) {
    double expected = 1.0;
    if (shadowed(shadow[x])) {
      expected = 0.0;
    } else if (x >= 2 && x < 10) {
      expected = std::min(1.0, (x - 1) / 9.0);
    } else if (x >= 14 && x < 36) {
      expected = std::min(1.0, (x - 13) / 6.0);
    }
    EXPECT_FLOAT_EQ(recovery[x], static_cast<float>(expected)) << "column " << x;
    EXPECT_EQ(recovery[n + x], 1.0f) << "column " << x << " of the line without shadow";
  }
}
