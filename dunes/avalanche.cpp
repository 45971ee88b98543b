#include "dunes/avalanche.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
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
  const float limit = static_cast<float>(max_drop);
  const float diagonal = static_cast<float>(std::numbers::sqrt2 * max_drop);
  // Excesses clamped at 0 are non-negative floats, whose bits order like
  // integers: an integer max reduction, which vectorises (a float one does
  // not without -ffast-math).
  auto excess = [](float a, float b, float lim) {
    const float e = std::fabs(a - b) - lim;
    return std::bit_cast<std::int32_t>(e > 0.0f ? e : 0.0f);
  };
  auto larger = [](std::int32_t a, std::int32_t b) { return a > b ? a : b; };
  const std::int32_t bits = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, rows, kRowBlock), std::int32_t{0},
      [&](const tbb::blocked_range<int>& r, std::int32_t m) {
        for (int row = r.begin(); row < r.end(); ++row) {
          const float* __restrict c = &h(0, row);
          const float* __restrict s = &h(0, row + 1 == rows ? 0 : row + 1);
          // Each edge once: east, south, south-east, south-west.
          auto cell = [&](int x, int xl, int xr) {
            return larger(larger(excess(c[x], c[xr], limit), excess(c[x], s[x], limit)),
                          larger(excess(c[x], s[xr], diagonal), excess(c[x], s[xl], diagonal)));
          };
          std::int32_t row_max = larger(cell(0, w - 1, 1), cell(w - 1, w - 2, 0));
          for (int x = 1; x + 1 < w; ++x) row_max = larger(row_max, cell(x, x - 1, x + 1));
          m = larger(m, row_max);
        }
        return m;
      },
      [](std::int32_t a, std::int32_t b) { return std::max(a, b); }, tbb::simple_partitioner());
  return static_cast<double>(std::bit_cast<float>(bits));
}

int avalanche(terrain::HeightField& h, double max_drop, int max_sweeps, double tolerance) {
  std::vector<float> scratch;
  return avalanche(h, max_drop, max_sweeps, tolerance, scratch);
}

int avalanche(terrain::HeightField& h, double max_drop, int max_sweeps, double tolerance,
              std::vector<float>& next) {
  const int w = h.width(), rows = h.height();
  next.resize(h.size());
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
  // Convergence is checked every few sweeps, by a separate vectorised pass.
  constexpr int kCheckEvery = 8;
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    if (tolerance >= 0 && sweep % kCheckEvery == 0 && max_excess(h, max_drop) <= tolerance) {
      return sweep;
    }
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
