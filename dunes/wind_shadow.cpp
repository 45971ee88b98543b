#include "dunes/wind_shadow.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <utility>

namespace drift::dunes {

namespace {

// Lines per task, swept side by side: independent recurrences overlap their
// latency, and 4 rows a power-of-two stride apart still fit the ways of one
// L1 set (16 did not). A fixed partition, and lines do not interact: the
// same bits for any thread count.
constexpr int kLineBlock = 4;

int wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

// The columns a line is followed: `warm_up` before column 0 (a lap at most:
// no sample further upwind can still cast a shadow, as the shadow line falls
// by more than the field's height range over them), then the field's width
// and `ahead` more for the distances.
struct Span {
  int warm_up, ahead;
};

// Shadow flags of lines [j0, j1) at columns [0, n + ahead): each sample below
// the shadow line cast by the samples upwind of it.
// flags[x * kLineBlock + (j - j0)].
void mark_shadowed(const terrain::HeightField& h, double t, double drop_per_column, Span span,
                   int j0, int j1, std::vector<std::uint8_t>& flags) {
  const int n = h.width(), rows = h.height();
  std::array<double, kLineBlock> carried;
  carried.fill(-1e300);
  const float* data = h.data();
  for (int x = -span.warm_up; x < n + span.ahead; ++x) {
    const int column = wrap(x, n);
    const Crossing c = crossing(t, x);
    const int first = wrap(j0 + c.row, rows);
    std::uint8_t* flag = &flags[static_cast<std::size_t>(x < 0 ? 0 : x) * kLineBlock];
    for (int k = 0; k < j1 - j0; ++k) {
      const int row = first + k < rows ? first + k : first + k - rows;
      const float* at = data + static_cast<std::size_t>(row) * n + column;
      double v = *at;
      if (c.frac != 0.0) {
        const float* below = row + 1 == rows ? data + column : at + n;
        v = (1.0 - c.frac) * v + c.frac * *below;
      }
      double& line = carried[k];
      line -= drop_per_column;
      if (x >= 0) flag[k] = v < line;
      line = std::max(line, v);
    }
  }
}

// Per sample of lines [j0, j1) at columns [0, n): its flag and the columns to
// the next shadowed sample downwind, at most `limit`.
void measure_reach(int n, int limit, Span span, int j0, int j1,
                   const std::vector<std::uint8_t>& flags, ShadowMap& shadow) {
  for (int j = j0; j < j1; ++j) {
    int next = 1 << 30;  // no shadow seen yet
    for (int x = n + span.ahead - 1; x >= 0; --x) {
      const bool flagged = flags[static_cast<std::size_t>(x) * kLineBlock + (j - j0)] != 0;
      if (x < n) {
        const int reach = std::min(next - x, limit);
        shadow[static_cast<std::size_t>(j) * n + x] =
            static_cast<std::uint16_t>((reach << 1) | (flagged ? 1 : 0));
      }
      if (flagged) next = x;
    }
  }
}

// Columns before column 0 that a line must be followed for.
int warm_up_columns(const terrain::HeightField& h, double drop_per_column) {
  using Range = std::pair<float, float>;
  const Range range = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, h.size(), 1 << 16), Range{1e30f, -1e30f},
      [&](const tbb::blocked_range<std::size_t>& r, Range m) {
        float lo = m.first, hi = m.second;  // selects: the loop vectorises
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
          const float v = h.values()[i];
          lo = v < lo ? v : lo;
          hi = v > hi ? v : hi;
        }
        return Range{lo, hi};
      },
      [](Range a, Range b) {
        return Range{std::min(a.first, b.first), std::max(a.second, b.second)};
      });
  const double columns = (static_cast<double>(range.second) - range.first) / drop_per_column + 2;
  return static_cast<int>(std::min<double>(h.width(), columns));
}

}  // namespace

void wind_shadow(const terrain::HeightField& h, double rows_per_column, double drop_per_cell,
                 double max_columns, ShadowMap& shadow) {
  assert(std::fabs(rows_per_column) <= 1.0 && h.width() <= 32767 && drop_per_cell > 0);
  const int n = h.width(), rows = h.height();
  shadow.resize(h.size());
  // A column step is sqrt(1 + t^2) cells along the wind.
  const double drop_per_column = drop_per_cell * std::sqrt(1.0 + rows_per_column * rows_per_column);
  const int limit = static_cast<int>(std::min<double>(n, std::ceil(max_columns) + 1));
  const Span span{warm_up_columns(h, drop_per_column), limit};
  tbb::parallel_for(
      tbb::blocked_range<int>(0, rows, kLineBlock),
      [&](const tbb::blocked_range<int>& r) {
        thread_local std::vector<std::uint8_t> flags;
        flags.resize(static_cast<std::size_t>(n + span.ahead) * kLineBlock);
        mark_shadowed(h, rows_per_column, drop_per_column, span, r.begin(), r.end(), flags);
        measure_reach(n, limit, span, r.begin(), r.end(), flags, shadow);
      },
      tbb::simple_partitioner());
}

Crossing crossing(double rows_per_column, int x) {
  const double y = rows_per_column * x;
  const double row = std::floor(y);
  return {static_cast<int>(row), y - row};
}

}  // namespace drift::dunes
