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

// The largest drops across the edges of the square lattice: max_drop along
// its axes, sqrt(2) max_drop along its diagonals.
struct EdgeLimits {
  float axis;      // (x, r) - (x + 1, r) and (x, r) - (x, r + 1)
  float diagonal;  // (x, r) - (x + 1, r + 1) and (x, r) - (x - 1, r + 1)
};

EdgeLimits edge_limits(double max_drop) {
  return {static_cast<float>(max_drop), static_cast<float>(max_drop * std::numbers::sqrt2)};
}

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
// The wrapped diagonals (south-east of the last column, south-west of the
// first) are left out: only the wrapped cells would read them, and those
// work their fluxes out from the heights (relax_row).
DRIFT_SIMD_KERNEL void south_fluxes_kernel(const float* __restrict c, const float* __restrict s,
                                           int w, const EdgeLimits& lim, float* __restrict south,
                                           float* __restrict south_east,
                                           float* __restrict south_west) {
  const float axis = lim.axis, diagonal = lim.diagonal;
  for (int x = 0; x < w; ++x) south[x] = flux(c[x], s[x], axis);
  for (int x = 0; x + 1 < w; ++x) south_east[x] = flux(c[x], s[x + 1], diagonal);
  for (int x = 1; x < w; ++x) south_west[x] = flux(c[x], s[x - 1], diagonal);
}
DRIFT_SIMD_TWINS(south_fluxes, south_fluxes_kernel,
                 (const float* c, const float* s, int w, const EdgeLimits& lim, float* south,
                  float* south_east, float* south_west),
                 (c, s, w, lim, south, south_east, south_west))

// Cells [begin, end) of row c, given the fluxes across their north edges
// (`a_`: the row above's south fluxes): their new heights, and their south
// fluxes, towards row s, kept for the row below. Reads columns begin - 1 to
// end. East-west fluxes are computed from both sides (the same expression,
// so the same bits): cheaper than a pass through memory. The sum runs in the
// order of the 8 neighbours W, E, N, S, NW, NE, SW, SE.
DRIFT_SIMD_KERNEL void relax_span(const float* __restrict c, const float* __restrict s, int begin,
                                  int end, const EdgeLimits& lim, const float* __restrict a_s,
                                  const float* __restrict a_se, const float* __restrict a_sw,
                                  float* __restrict south, float* __restrict south_east,
                                  float* __restrict south_west, float* __restrict out) {
  // One level of inlining, no lambda: either loses `restrict` for GCC, which
  // then does not vectorise the loop.
  const float edge = lim.axis, diagonal = lim.diagonal;
  for (int x = begin; x < end; ++x) {
    const float to_s = flux(c[x], s[x], edge);
    const float to_se = flux(c[x], s[x + 1], diagonal);
    const float to_sw = flux(c[x], s[x - 1], diagonal);
    south[x] = to_s;
    south_east[x] = to_se;
    south_west[x] = to_sw;
    const float axis = -flux(c[x - 1], c[x], edge) + flux(c[x], c[x + 1], edge) + -a_s[x] + to_s;
    const float diag = -a_se[x - 1] + -a_sw[x + 1] + to_sw + to_se;
    out[x] = c[x] - (axis + diag);
  }
}

// A row's inner columns, in place.
DRIFT_SIMD_KERNEL void relax_inner_kernel(const float* c, const float* s, int w,
                                          const EdgeLimits& lim, const float* a_s,
                                          const float* a_se, const float* a_sw, float* south,
                                          float* south_east, float* south_west, float* out) {
  relax_span(c, s, 1, w - 1, lim, a_s, a_se, a_sw, south, south_east, south_west, out);
}
DRIFT_SIMD_TWINS(relax_inner, relax_inner_kernel,
                 (const float* c, const float* s, int w, const EdgeLimits& lim, const float* a_s,
                  const float* a_se, const float* a_sw, float* south, float* south_east,
                  float* south_west, float* out),
                 (c, s, w, lim, a_s, a_se, a_sw, south, south_east, south_west, out))

// A whole row, given the row south of it (`s`, the lattice's next row): the
// inner columns in place; each wrapped column from a 3 x 3 copy of its
// lattice neighbourhood (dunes/lattice.h), its fluxes across the north edges
// worked out from the heights (the very expression its neighbours evaluate,
// so the same bits), so that every cell runs the same code. `row` and `h`
// locate the wrapped neighbours.
void relax_row(const terrain::HeightField& h, int row, const float* s, int shift,
               const EdgeLimits& lim, const float* a_s, const float* a_se, const float* a_sw,
               float* south, float* south_east, float* south_west, float* out) {
  const int w = h.width();
  const float* c = &h(0, row);
  relax_inner(c, s, w, lim, a_s, a_se, a_sw, south, south_east, south_west, out);
  for (const int x : {0, w - 1}) {
    const Neighbourhood nb = neighbourhood(h, x, row, shift);
    const float a_s3[3] = {0.0f, flux(nb[0][1], nb[1][1], lim.axis), 0.0f};
    const float a_se3[3] = {flux(nb[0][0], nb[1][1], lim.diagonal), 0.0f, 0.0f};
    const float a_sw3[3] = {0.0f, 0.0f, flux(nb[0][2], nb[1][1], lim.diagonal)};
    float south3[3], south_east3[3], south_west3[3], out3[3];
    relax_span(nb[1].data(), nb[2].data(), 1, 2, lim, a_s3, a_se3, a_sw3, south3, south_east3,
               south_west3, out3);
    south[x] = south3[1];
    south_east[x] = south_east3[1];
    south_west[x] = south_west3[1];
    out[x] = out3[1];
  }
}

}  // namespace

double max_excess(const terrain::HeightField& h, double max_drop, int shift) {
  const int w = h.width(), rows = h.height();
  const EdgeLimits lim = edge_limits(max_drop);
  // Excesses clamped at 0 are non-negative floats, whose bits order like
  // integers: an integer max reduction, which vectorises (a float one does
  // not without -ffast-math).
  auto excess = [](float a, float b, float l) {
    const float e = std::fabs(a - b) - l;
    return std::bit_cast<std::int32_t>(e > 0.0f ? e : 0.0f);
  };
  auto larger = [](std::int32_t a, std::int32_t b) { return a > b ? a : b; };
  // Each edge once: east, south, south-east, south-west.
  auto edges = [&](float c, float e, float s, float se, float sw) {
    return larger(larger(excess(c, e, lim.axis), excess(c, s, lim.axis)),
                  larger(excess(c, se, lim.diagonal), excess(c, sw, lim.diagonal)));
  };
  const std::int32_t bits = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, rows, kRowBlock), std::int32_t{0},
      [&](const tbb::blocked_range<int>& r, std::int32_t m) {
        thread_local std::vector<float> wrapped;
        for (int row = r.begin(); row < r.end(); ++row) {
          const float* __restrict c = &h(0, row);
          const float* __restrict s = lattice_row(h, row + 1, shift, wrapped);
          std::int32_t row_max = 0;
          for (const int x : {0, w - 1}) {
            const Neighbourhood nb = neighbourhood(h, x, row, shift);
            row_max = larger(row_max, edges(nb[1][1], nb[1][2], nb[2][1], nb[2][2], nb[2][0]));
          }
          for (int x = 1; x + 1 < w; ++x)
            row_max = larger(row_max, edges(c[x], c[x + 1], s[x], s[x + 1], s[x - 1]));
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
  const EdgeLimits lim = edge_limits(max_drop);
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
          south_fluxes(lattice_row(h, first - 1, shift, wrapped), &h(0, first), w, lim, above[0],
                       above[1], above[2]);
          for (int row = first; row < r.end(); ++row) {
            relax_row(h, row, lattice_row(h, row + 1, shift, wrapped), shift, lim, above[0],
                      above[1], above[2], below[0], below[1], below[2],
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
