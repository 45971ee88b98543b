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

#include "dunes/lattice.h"
#include "terrain/simd.h"

namespace drift::dunes {

namespace {

// Rows [begin, end) in fixed blocks: the partition (and so every float
// operation) does not depend on the number of threads.
constexpr int kRowBlock = 16;

// Flux from a down to b across an edge whose drop may be at most `lim`: a
// ninth of the excess (8 edges: no overshoot). d - clamp(d) is d - lim above
// the limit and d + lim below it (the very roundings of those) and 0 within:
// min, max and no branch, so row loops vectorise. flux(b, a) = -flux(a, b)
// exactly (negation and clamping are symmetric), which lets each edge's flux
// be computed once per sweep where that is cheaper: what one cell loses is
// bit for bit what the other gains.
DRIFT_SIMD_KERNEL float flux(float a, float b, float lim) {
  const float d = a - b;
  return (d - std::min(std::max(d, -lim), lim)) * (1.0f / 9.0f);
}

// The fluxes across the edges between row c and the row s south of it, per
// column x: to (x, south) in `south`, to (x + 1, south) in `south_east`, to
// (x - 1, south) in `south_west` (columns wrap).
DRIFT_SIMD_KERNEL void south_fluxes_kernel(const float* __restrict c, const float* __restrict s,
                                           int w, float limit, float diagonal,
                                           float* __restrict south, float* __restrict south_east,
                                           float* __restrict south_west) {
  for (int x = 0; x < w; ++x) south[x] = flux(c[x], s[x], limit);
  for (int x = 0; x + 1 < w; ++x) south_east[x] = flux(c[x], s[x + 1], diagonal);
  south_east[w - 1] = flux(c[w - 1], s[0], diagonal);
  south_west[0] = flux(c[0], s[w - 1], diagonal);
  for (int x = 1; x < w; ++x) south_west[x] = flux(c[x], s[x - 1], diagonal);
}
DRIFT_SIMD_TWINS(south_fluxes, south_fluxes_kernel,
                 (const float* c, const float* s, int w, float limit, float diagonal, float* south,
                  float* south_east, float* south_west),
                 (c, s, w, limit, diagonal, south, south_east, south_west))

// Cells [begin, end) of row c, given the fluxes across their north edges
// (`a_`: the row above's south fluxes): their new heights, and their south
// fluxes, towards row s, kept for the row below. Reads columns begin - 1 to
// end. East-west fluxes are computed from both sides (the same expression,
// so the same bits): cheaper than a pass through memory. The sum runs in the
// order of the 8 neighbours W, E, N, S, NW, NE, SW, SE.
DRIFT_SIMD_KERNEL void relax_span(const float* __restrict c, const float* __restrict s, int begin,
                                  int end, float limit, float diagonal, const float* __restrict a_s,
                                  const float* __restrict a_se, const float* __restrict a_sw,
                                  float* __restrict south, float* __restrict south_east,
                                  float* __restrict south_west, float* __restrict out) {
  // One level of inlining, no lambda: either loses `restrict` for GCC, which
  // then does not vectorise the loop.
  for (int x = begin; x < end; ++x) {
    const float to_s = flux(c[x], s[x], limit);
    const float to_se = flux(c[x], s[x + 1], diagonal);
    const float to_sw = flux(c[x], s[x - 1], diagonal);
    south[x] = to_s;
    south_east[x] = to_se;
    south_west[x] = to_sw;
    const float axis = -flux(c[x - 1], c[x], limit) + flux(c[x], c[x + 1], limit) + -a_s[x] + to_s;
    const float diag = -a_se[x - 1] + -a_sw[x + 1] + to_sw + to_se;
    out[x] = c[x] - (axis + diag);
  }
}

// A whole row, given the row south of it (`s`: on the wind lattice the row
// past the last is row 0 shifted, dunes/lattice.h; within a row, columns
// wrap plainly): the inner columns in place, each wrapped column through a
// 3-column copy of its neighbourhood, so that every cell runs the same code.
DRIFT_SIMD_KERNEL void relax_row_kernel(const float* c, const float* s, int w, float limit,
                                        float diagonal, const float* a_s, const float* a_se,
                                        const float* a_sw, float* south, float* south_east,
                                        float* south_west, float* out) {
  relax_span(c, s, 1, w - 1, limit, diagonal, a_s, a_se, a_sw, south, south_east, south_west, out);
  for (const int x : {0, w - 1}) {
    const int l = x == 0 ? w - 1 : x - 1, r = x + 1 == w ? 0 : x + 1;
    const float c3[3] = {c[l], c[x], c[r]}, s3[3] = {s[l], s[x], s[r]};
    const float a_s3[3] = {0.0f, a_s[x], 0.0f}, a_se3[3] = {a_se[l], 0.0f, 0.0f};
    const float a_sw3[3] = {0.0f, 0.0f, a_sw[r]};
    float south3[3], south_east3[3], south_west3[3], out3[3];
    relax_span(c3, s3, 1, 2, limit, diagonal, a_s3, a_se3, a_sw3, south3, south_east3, south_west3,
               out3);
    south[x] = south3[1];
    south_east[x] = south_east3[1];
    south_west[x] = south_west3[1];
    out[x] = out3[1];
  }
}
DRIFT_SIMD_TWINS(relax_row, relax_row_kernel,
                 (const float* c, const float* s, int w, float limit, float diagonal,
                  const float* a_s, const float* a_se, const float* a_sw, float* south,
                  float* south_east, float* south_west, float* out),
                 (c, s, w, limit, diagonal, a_s, a_se, a_sw, south, south_east, south_west, out))

}  // namespace

double max_excess(const terrain::HeightField& h, double max_drop, int shift) {
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
        thread_local std::vector<float> wrapped;  // the row past the last, shifted
        for (int row = r.begin(); row < r.end(); ++row) {
          const float* __restrict c = &h(0, row);
          const float* __restrict s = lattice_row(h, row + 1, shift, wrapped);
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

int avalanche(terrain::HeightField& h, double max_drop, int max_sweeps, double tolerance,
              int shift) {
  std::vector<float> scratch;
  return avalanche(h, max_drop, max_sweeps, tolerance, scratch, shift);
}

int avalanche(terrain::HeightField& h, double max_drop, int max_sweeps, double tolerance,
              std::vector<float>& next, int shift) {
  const int w = h.width(), rows = h.height();
  next.resize(h.size());
  const float limit = static_cast<float>(max_drop);
  const float diagonal = static_cast<float>(std::numbers::sqrt2 * max_drop);
  // Convergence is checked every few sweeps, by a separate vectorised pass.
  constexpr int kCheckEvery = 8;
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    if (tolerance >= 0 && sweep % kCheckEvery == 0 && max_excess(h, max_drop, shift) <= tolerance) {
      return sweep;
    }
    tbb::parallel_for(
        tbb::blocked_range<int>(0, rows, kRowBlock),
        [&](const tbb::blocked_range<int>& r) {
          // Per row: the fluxes across its north edges (the row above's
          // south fluxes), its south edges and its east edges. The block's
          // first row needs the south fluxes of the row above it.
          thread_local std::vector<float> buffers;
          // Each buffer 32 floats further on than a multiple of the row: a
          // load that trails a store by 4 KiB looks to the CPU like it
          // depends on it (4K aliasing) and waits.
          const std::size_t stride = static_cast<std::size_t>(w) + 32;
          buffers.resize(6 * stride);
          float* above[3] = {buffers.data(), buffers.data() + stride, buffers.data() + 2 * stride};
          float* below[3] = {buffers.data() + 3 * stride, buffers.data() + 4 * stride,
                             buffers.data() + 5 * stride};
          thread_local std::vector<float> wrapped;  // a row past the edge, shifted
          const int first = r.begin();
          south_fluxes(lattice_row(h, first - 1, shift, wrapped), &h(0, first), w, limit, diagonal,
                       above[0], above[1], above[2]);
          for (int row = first; row < r.end(); ++row) {
            relax_row(&h(0, row), lattice_row(h, row + 1, shift, wrapped), w, limit, diagonal,
                      above[0], above[1], above[2], below[0], below[1], below[2],
                      &next[static_cast<std::size_t>(row) * w]);
            std::swap(above, below);
          }
        },
        tbb::simple_partitioner());
    std::swap(next, h.values());
  }
  return max_sweeps;
}

}  // namespace drift::dunes
