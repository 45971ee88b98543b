#include "dunes/avalanche.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

namespace drift::dunes {

namespace {

// Rows [begin, end) in fixed blocks: the partition (and so every float
// operation) does not depend on the number of threads.
constexpr int kRowBlock = 16;

}  // namespace

double max_excess(const terrain::HeightField& h, double max_drop) {
  const int w = h.width(), rows = h.height();
  const double diagonal = std::numbers::sqrt2 * max_drop;
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, rows, kRowBlock), 0.0,
      [&](const tbb::blocked_range<int>& r, double m) {
        for (int row = r.begin(); row < r.end(); ++row) {
          const float* c = &h(0, row);
          const float* s = &h(0, (row + 1) % rows);
          for (int x = 0; x < w; ++x) {
            const int xr = x + 1 == w ? 0 : x + 1, xl = x == 0 ? w - 1 : x - 1;
            m = std::max({m, std::fabs(c[x] - c[xr]) - max_drop, std::fabs(c[x] - s[x]) - max_drop,
                          std::fabs(c[x] - s[xr]) - diagonal, std::fabs(c[x] - s[xl]) - diagonal});
          }
        }
        return m;
      },
      [](double a, double b) { return std::max(a, b); }, tbb::simple_partitioner());
}

int avalanche(terrain::HeightField& h, double max_drop, int max_sweeps, double tolerance) {
  const int w = h.width(), rows = h.height();
  std::vector<float> next(h.size());
  const float limit = static_cast<float>(max_drop);
  const float diagonal_limit = static_cast<float>(std::numbers::sqrt2 * max_drop);
  // Flux out of a cell across one of its 8 edges: a ninth of the excess drop
  // (8 edges: no overshoot). Diagonal neighbours are sqrt(2) cells away, so
  // the slope itself, not only its east and north parts, stays within about
  // 8 % of the limit. Branch free, so the row loop vectorises; exactly
  // antisymmetric in (a, b).
  auto flux = [](float a, float b, float lim) {
    const float d = a - b;
    return (std::max(d - lim, 0.0f) + std::min(d + lim, 0.0f)) * (1.0f / 9.0f);
  };
  // Convergence is checked every few sweeps, outside the vectorised loop.
  constexpr int kCheckEvery = 8;
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    if (sweep % kCheckEvery == 0 && max_excess(h, max_drop) <= tolerance) return sweep;
    tbb::parallel_for(
        tbb::blocked_range<int>(0, rows, kRowBlock),
        [&](const tbb::blocked_range<int>& r) {
          for (int row = r.begin(); row < r.end(); ++row) {
            const float* __restrict c = &h(0, row);
            const float* __restrict n = &h(0, row == 0 ? rows - 1 : row - 1);
            const float* __restrict s = &h(0, row + 1 == rows ? 0 : row + 1);
            float* __restrict out = &next[static_cast<std::size_t>(row) * w];
            // The same expression for an edge from both sides: the flux one
            // cell loses is bit for bit the flux the other gains.
            auto cell = [&](int x, int xl, int xr) {
              const float v = c[x];
              const float axis = flux(v, c[xl], limit) + flux(v, c[xr], limit) +
                                 flux(v, n[x], limit) + flux(v, s[x], limit);
              const float diag = flux(v, n[xl], diagonal_limit) + flux(v, n[xr], diagonal_limit) +
                                 flux(v, s[xl], diagonal_limit) + flux(v, s[xr], diagonal_limit);
              out[x] = v - (axis + diag);
            };
            cell(0, w - 1, 1);
            for (int x = 1; x + 1 < w; ++x) cell(x, x - 1, x + 1);
            cell(w - 1, w - 2, 0);
          }
        },
        tbb::simple_partitioner());
    std::swap(next, h.values());
  }
  return max_sweeps;
}

}  // namespace drift::dunes
