#include "dunes/avalanche.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <vector>

#include "dunes/lattice.h"
#include "dunes/sweep_tiles.h"
#include "terrain/simd.h"

namespace drift::dunes {

namespace {

// The excess drop from a down to b across an edge whose drop may be at most
// `lim`: d - clamp(d) is d - lim above the limit and d + lim below it (the
// very roundings of those) and 0 within: min, max and no branch, so row
// loops vectorise. A sweep moves a ninth of each cell's summed excesses (8
// edges: no overshoot), one multiplication a cell rather than one an edge.
// excess(b, a) = -excess(a, b) exactly (negation and clamping are
// symmetric), which lets each edge's excess be computed once per sweep where
// that is cheaper, and across every edge what one side counts, the other
// counts negated.
DRIFT_SIMD_KERNEL float excess(float a, float b, float lim) {
  const float d = a - b;
  return d - std::min(std::max(d, -lim), lim);
}

// A strip's per-row buffers of excesses are indexed from its first column
// x0 (index i: column x0 + i), and also hold index -1 and the strip's
// length: what the strip's cells of the row below read beside their own.

// The two excesses across a strip's ends that the row below reads beside
// the strip's own: from column x0 - 1 south-east to x0, and from x1
// south-west to x1 - 1 (columns wrap).
inline void strip_ends(const float* c, const float* s, int w, int x0, int x1, float diagonal,
                       float* south_east, float* south_west) {
  const int before = x0 == 0 ? w - 1 : x0 - 1, after = x1 == w ? 0 : x1;
  south_east[-1] = excess(c[before], s[x0], diagonal);
  south_west[x1 - x0] = excess(c[after], s[x1 - 1], diagonal);
}

// The excesses across the edges between the strip [x0, x1) of row c and
// the row s south of it: to (x, south) in `south`, to (x + 1, south) in
// `south_east`, to (x - 1, south) in `south_west`.
DRIFT_SIMD_KERNEL void south_excesses_kernel(const float* c, const float* s, int w, int x0, int x1,
                                             float limit, float diagonal, float* __restrict south,
                                             float* __restrict south_east,
                                             float* __restrict south_west) {
  const int n = x1 - x0;
  const float* __restrict cs = c + x0;
  const float* __restrict ss = s + x0;
  for (int i = 0; i < n; ++i) south[i] = excess(cs[i], ss[i], limit);
  for (int i = 0; i + 1 < n; ++i) south_east[i] = excess(cs[i], ss[i + 1], diagonal);
  for (int i = 1; i < n; ++i) south_west[i] = excess(cs[i], ss[i - 1], diagonal);
  strip_ends(c, s, w, x0, x1, diagonal, south_east, south_west);
}
DRIFT_SIMD_TWINS(south_excesses, south_excesses_kernel,
                 (const float* c, const float* s, int w, int x0, int x1, float limit,
                  float diagonal, float* south, float* south_east, float* south_west),
                 (c, s, w, x0, x1, limit, diagonal, south, south_east, south_west))

// Cells [begin, end) of row c, given the excesses across their north edges
// (`a_`: the row above's south excesses): their new heights, and their
// south excesses, towards row s, kept for the row below. Reads columns
// begin - 1 to end. East-west excesses are computed from both sides (the
// same expression, so the same bits): cheaper than a pass through memory.
// The sum runs in the order of the 8 neighbours W, E, N, S, NW, NE, SW, SE.
DRIFT_SIMD_KERNEL void relax_span(const float* __restrict c, const float* __restrict s, int begin,
                                  int end, float limit, float diagonal, const float* __restrict a_s,
                                  const float* __restrict a_se, const float* __restrict a_sw,
                                  float* __restrict south, float* __restrict south_east,
                                  float* __restrict south_west, float* __restrict out) {
  // One level of inlining, no lambda: either loses `restrict` for GCC, which
  // then does not vectorise the loop.
  for (int x = begin; x < end; ++x) {
    const float to_s = excess(c[x], s[x], limit);
    const float to_se = excess(c[x], s[x + 1], diagonal);
    const float to_sw = excess(c[x], s[x - 1], diagonal);
    south[x] = to_s;
    south_east[x] = to_se;
    south_west[x] = to_sw;
    const float axis =
        -excess(c[x - 1], c[x], limit) + excess(c[x], c[x + 1], limit) + -a_s[x] + to_s;
    const float diag = -a_se[x - 1] + -a_sw[x + 1] + to_sw + to_se;
    out[x] = c[x] - (axis + diag) * (1.0f / 9.0f);
  }
}

// The strip [x0, x1) of a row, given the row south of it (`s`: on the wind
// lattice the row past the last is row 0 shifted, dunes/lattice.h; within a
// row, columns wrap plainly): its new heights in `out` (the row's) and its
// south excesses. The inner columns in place, a wrapped column (0 or w - 1)
// through a 3-column copy of its neighbourhood, so that every cell runs the
// same code.
DRIFT_SIMD_KERNEL void relax_strip_kernel(const float* c, const float* s, int w, int x0, int x1,
                                          float limit, float diagonal, const float* a_s,
                                          const float* a_se, const float* a_sw, float* south,
                                          float* south_east, float* south_west, float* out) {
  const InnerColumns inner = inner_columns(x0, x1, w);
  relax_span(c + x0, s + x0, inner.begin - x0, inner.end - x0, limit, diagonal, a_s, a_se, a_sw,
             south, south_east, south_west, out + x0);
  for_wrapped_columns(x0, x1, w, [&](int x, int l, int r) {
    const int i = x - x0;
    const float c3[3] = {c[l], c[x], c[r]}, s3[3] = {s[l], s[x], s[r]};
    const float a_s3[3] = {0.0f, a_s[i], 0.0f}, a_se3[3] = {a_se[i - 1], 0.0f, 0.0f};
    const float a_sw3[3] = {0.0f, 0.0f, a_sw[i + 1]};
    float south3[3], south_east3[3], south_west3[3], out3[3];
    relax_span(c3, s3, 1, 2, limit, diagonal, a_s3, a_se3, a_sw3, south3, south_east3, south_west3,
               out3);
    south[i] = south3[1];
    south_east[i] = south_east3[1];
    south_west[i] = south_west3[1];
    out[x] = out3[1];
  });
  strip_ends(c, s, w, x0, x1, diagonal, south_east, south_west);
}
DRIFT_SIMD_TWINS(relax_strip, relax_strip_kernel,
                 (const float* c, const float* s, int w, int x0, int x1, float limit,
                  float diagonal, const float* a_s, const float* a_se, const float* a_sw,
                  float* south, float* south_east, float* south_west, float* out),
                 (c, s, w, x0, x1, limit, diagonal, a_s, a_se, a_sw, south, south_east, south_west,
                  out))

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
  const LatticeRows row(h, shift);
  // The maximum does not depend on the order tiles finish in.
  std::atomic<std::int32_t> largest{0};
  for_tiles(w, rows, [&](const Tile& t) {
    std::int32_t m = 0;
    for (int r = t.first_row; r < t.end_row; ++r) {
      const float* __restrict c = row[r];
      const float* __restrict s = row[r + 1];
      // Each edge once: east, south, south-east, south-west.
      for_strip_columns(t, w, [&](int x, int xl, int xr) {
        m = larger(m, larger(larger(excess(c[x], c[xr], limit), excess(c[x], s[x], limit)),
                             larger(excess(c[x], s[xr], diagonal), excess(c[x], s[xl], diagonal))));
      });
    }
    std::int32_t seen = largest.load();
    while (m > seen && !largest.compare_exchange_weak(seen, m)) {
    }
  });
  const std::int32_t bits = largest.load();
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
    const LatticeRows row(h, shift);
    for_tiles(w, rows, [&](const Tile& t) {
      // Per row: the excesses across its north edges (the row above's
      // south excesses), its south edges and its east edges. The tile's
      // first row needs the south excesses of the row above it.
      thread_local std::vector<float> buffers;
      // Each buffer 32 floats further on than the strip and its two ends: a
      // load that trails a store by 4 KiB looks to the CPU like it depends
      // on it (4K aliasing) and waits.
      const std::size_t stride = static_cast<std::size_t>(t.x1 - t.x0) + 2 + 32;
      buffers.resize(6 * stride);
      auto buffer = [&](int k) { return buffers.data() + k * stride + 1; };
      float* above[3] = {buffer(0), buffer(1), buffer(2)};
      float* below[3] = {buffer(3), buffer(4), buffer(5)};
      south_excesses(row[t.first_row - 1], row[t.first_row], w, t.x0, t.x1, limit, diagonal,
                     above[0], above[1], above[2]);
      for (int r = t.first_row; r < t.end_row; ++r) {
        relax_strip(row[r], row[r + 1], w, t.x0, t.x1, limit, diagonal, above[0], above[1],
                    above[2], below[0], below[1], below[2], &next[static_cast<std::size_t>(r) * w]);
        std::swap(above, below);
      }
    });
    std::swap(next, h.values());
  }
  return max_sweeps;
}

}  // namespace drift::dunes
