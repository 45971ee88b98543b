#include "dunes/avalanche.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace drift::dunes {

namespace {

// Rows [begin, end) in fixed blocks: the partition (and so every float
// operation) does not depend on the number of threads.
constexpr int kRowBlock = 16;

}  // namespace

double max_edge_drop(const terrain::HeightField& h) {
  const int w = h.width(), rows = h.height();
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, rows, kRowBlock), 0.0,
      [&](const tbb::blocked_range<int>& r, double m) {
        for (int row = r.begin(); row < r.end(); ++row) {
          const float* c = &h(0, row);
          const float* s = &h(0, (row + 1) % rows);
          for (int x = 0; x < w; ++x) {
            const int xr = x + 1 == w ? 0 : x + 1;
            m = std::max({m, static_cast<double>(std::fabs(c[x] - c[xr])),
                          static_cast<double>(std::fabs(c[x] - s[x]))});
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
  // Flux out of a cell across one edge: a fifth of the excess drop.
  auto flux = [limit](float a, float b) {
    const float d = a - b;
    return d > limit ? (d - limit) * 0.2f : (d < -limit ? (d + limit) * 0.2f : 0.0f);
  };
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    const double worst = tbb::parallel_reduce(
        tbb::blocked_range<int>(0, rows, kRowBlock), 0.0,
        [&](const tbb::blocked_range<int>& r, double m) {
          for (int row = r.begin(); row < r.end(); ++row) {
            const float* c = &h(0, row);
            const float* n = &h(0, row == 0 ? rows - 1 : row - 1);
            const float* s = &h(0, row + 1 == rows ? 0 : row + 1);
            float* out = &next[static_cast<std::size_t>(row) * w];
            for (int x = 0; x < w; ++x) {
              const int xl = x == 0 ? w - 1 : x - 1, xr = x + 1 == w ? 0 : x + 1;
              const float v = c[x];
              // The same expression for an edge from both sides: the flux one
              // cell loses is bit for bit the flux the other gains.
              const float f = flux(v, c[xl]) + flux(v, c[xr]) + flux(v, n[x]) + flux(v, s[x]);
              out[x] = v - f;
              m = std::max(m, static_cast<double>(std::fabs(f)));
            }
          }
          return m;
        },
        [](double a, double b) { return std::max(a, b); }, tbb::simple_partitioner());
    if (worst == 0.0) return sweep;
    std::copy(next.begin(), next.end(), h.values().begin());
    // The largest flux is a fifth of the largest excess.
    if (worst * 5.0 <= tolerance) return sweep + 1;
  }
  return max_sweeps;
}

}  // namespace drift::dunes
