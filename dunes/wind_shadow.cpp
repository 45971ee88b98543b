#include "dunes/wind_shadow.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "terrain/simd.h"

namespace drift::dunes {

namespace {

// Lines per task, swept side by side: independent recurrences overlap their
// latency, and 4 rows a power-of-two stride apart still fit the ways of one
// L1 set (16 did not). A fixed partition, and lines do not interact: the
// same bits for any thread count.
constexpr int kLineBlock = 4;

// The columns a line (a row, closed on itself) is followed: `warm_up`
// before column 0 (no sample further upwind can still cast a shadow, as the
// shadow line falls by more than the field's height range over them), then
// the field's width and `ahead` more for the distances.
struct Span {
  int warm_up, ahead;
};

// The columns followed, unwrapped x in [-warm_up, n + ahead), in three
// runs that need no wrapping: the warm-up at the end of the row, the row,
// then its start again for the distances ahead (warm_up and ahead <= n).
struct Run {
  int begin, end;     // unwrapped columns
  int column_offset;  // added to x to give the row's column
};

std::array<Run, 3> runs(int n, Span span) {
  return {{{-span.warm_up, 0, n}, {0, n, 0}, {n, n + span.ahead, -n}}};
}

// A block's lines side by side in the lanes of one vector (GCC's vector
// extensions: two SSE2 registers in the baseline build, one AVX2 register
// in its twin; the same IEEE operation in every lane either way).
using LineDoubles = double __attribute__((vector_size(kLineBlock * sizeof(double))));
using LineInts = std::int32_t __attribute__((vector_size(kLineBlock * sizeof(std::int32_t))));

// Shadow flags of a block of kLineBlock rows at columns [0, n + ahead):
// each sample below the shadow line cast by the samples upwind of it, at
// flags[x * kLineBlock + lane], run by run (`runs`). Lane k
// follows row first_row + k (a short last block repeats its last row).
DRIFT_SIMD_KERNEL void mark_shadowed_kernel(const float* data, int n, double drop_per_column,
                                            const std::array<Run, 3>& runs,
                                            const std::int32_t* first_row, std::int32_t* flags) {
  static_assert(kLineBlock == 4, "the lanes below are written out for 4 lines");
  std::array<const float*, kLineBlock> line_row;
  for (int k = 0; k < kLineBlock; ++k)
    line_row[k] = data + static_cast<std::size_t>(first_row[k]) * n;
  LineDoubles carried = {-1e300, -1e300, -1e300, -1e300};
  for (const Run& run : runs) {
    for (int x = run.begin; x < run.end; ++x) {
      const int c = x + run.column_offset;
      const LineDoubles v = {line_row[0][c], line_row[1][c], line_row[2][c], line_row[3][c]};
      const LineDoubles line = carried - drop_per_column;
      if (x >= 0) {
        const LineInts flag = __builtin_convertvector(v < line, LineInts) & 1;
        std::memcpy(flags + static_cast<std::size_t>(x) * kLineBlock, &flag, sizeof flag);
      }
      carried = line < v ? v : line;  // std::max(line, v)
    }
  }
}
DRIFT_SIMD_TWINS(mark_shadowed, mark_shadowed_kernel,
                 (const float* data, int n, double drop_per_column, const std::array<Run, 3>& runs,
                  const std::int32_t* first_row, std::int32_t* flags),
                 (data, n, drop_per_column, runs, first_row, flags))

// Per sample of lines [j0, j1) (at most a block) at columns [0, n): its
// flag and the columns to the next shadowed sample downwind, at most
// `limit`. The block's lines in the lanes of a vector, branch free (the
// flags follow the relief, which no predictor guesses).
void measure_reach(int n, int limit, Span span, int j0, int j1,
                   const std::vector<std::int32_t>& flags, ShadowMap& shadow) {
  auto flag_at = [&](int x) {
    LineInts f;
    std::memcpy(&f, &flags[static_cast<std::size_t>(x) * kLineBlock], sizeof f);
    return f;
  };
  LineInts next = LineInts{} + (1 << 30);  // no shadow seen yet
  for (int x = n + span.ahead - 1; x >= n; --x) next = flag_at(x) != 0 ? x : next;
  std::uint16_t* out = &shadow[static_cast<std::size_t>(j0) * n];
  // A whole block stores every lane with no test (the constant unrolls).
  auto walk = [&](auto whole) {
    const int lines = decltype(whole)::value ? kLineBlock : j1 - j0;
    for (int x = n - 1; x >= 0; --x) {
      const LineInts flagged = flag_at(x);
      const LineInts reach = next - x;
      const LineInts packed = ((reach < limit ? reach : limit) << 1) | flagged;
#pragma GCC unroll 4
      for (int k = 0; k < lines; ++k) {
        out[static_cast<std::size_t>(k) * n + x] = static_cast<std::uint16_t>(packed[k]);
      }
      next = flagged != 0 ? x : next;
    }
  };
  if (j1 - j0 == kLineBlock) {
    walk(std::true_type{});
  } else {
    walk(std::false_type{});
  }
}

// Columns before column 0 that a row must be followed for: past a lap it
// has come round to its own start.
int warm_up_columns(int width, HeightRange range, double drop_per_column) {
  const double columns = (static_cast<double>(range.hi) - range.lo) / drop_per_column + 2;
  return static_cast<int>(std::min<double>(width, columns));
}

// A line's shadow flags as bits (bit x % 64 of word x / 64), so that runs
// in and out of shadow are found a word at a time: a line has some thirty
// shadows, mostly a few samples long.
class ShadowBits {
 public:
  // The words in a thread's buffer, kept from line to line: no allocation
  // per line.
  ShadowBits(const std::uint16_t* s, int n) : words_(buffer()), n_(n), count_((n + 63) / 64) {
    words_.assign(static_cast<std::size_t>(count_), std::uint64_t{0});
    int i = 0;
#if defined(__SSE2__)
    // Sixteen flags per step: compare, narrow to bytes, one bit each.
    const __m128i one = _mm_set1_epi16(1);
    for (; i + 16 <= n; i += 16) {
      const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + i));
      const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + i + 8));
      const __m128i flags = _mm_packs_epi16(_mm_cmpeq_epi16(_mm_and_si128(a, one), one),
                                            _mm_cmpeq_epi16(_mm_and_si128(b, one), one));
      const auto mask = static_cast<std::uint64_t>(_mm_movemask_epi8(flags) & 0xffff);
      words_[static_cast<std::size_t>(i >> 6)] |= mask << (i & 63);
    }
#endif
    for (; i < n; ++i) {
      if (shadowed(s[i])) words_[static_cast<std::size_t>(i >> 6)] |= std::uint64_t{1} << (i & 63);
    }
  }

  // The first sample in [from, n) whose flag is `flag`, or n.
  int next(int from, bool flag) const {
    if (from >= n_) return n_;
    std::size_t w = static_cast<std::size_t>(from >> 6);
    std::uint64_t word = (flag ? words_[w] : ~words_[w]) & (~std::uint64_t{0} << (from & 63));
    while (word == 0) {
      if (++w == static_cast<std::size_t>(count_)) return n_;
      word = flag ? words_[w] : ~words_[w];
    }
    return std::min(n_, static_cast<int>(w * 64) + std::countr_zero(word));
  }

 private:
  static std::vector<std::uint64_t>& buffer() {
    thread_local std::vector<std::uint64_t> words;
    return words;
  }
  std::vector<std::uint64_t>& words_;
  int n_, count_;
};

// The lift's recovery along one row of n samples of the shadow map (see
// shadow_recovery()), which closes on itself.
void recover_line(const std::uint16_t* s, int n, double ratio, float* out) {
  // The previous shadow: where it ended (the first sample past it, <= 0 for
  // one before column 0) and its length (0: none). At column 0, the row's
  // last shadowed run, counted back from its end.
  int prev_run = 0;
  int last = n - 1;
  while (last >= 0 && !shadowed(s[last])) --last;
  for (int x = last; x >= 0 && shadowed(s[x]); --x) ++prev_run;
  int prev_end = last + 1 - n;
  // Mostly 1: shadows are a few samples long and their ramps short, so fill,
  // then visit the shadows (found a word of flags at a time) and the ramps
  // behind them.
  std::fill(out, out + n, 1.0f);
  const ShadowBits bits(s, n);
  auto ramp = [&](int until) {  // after the previous shadow, up to `until`
    if (prev_run == 0) return;
    const float slope = 1.0f / static_cast<float>(ratio * prev_run);
    for (int x = std::max(prev_end, 0); x < until; ++x) {
      const float f = static_cast<float>(x - prev_end + 1) * slope;
      if (f >= 1.0f) break;
      out[x] = f;
    }
  };
  for (int a = bits.next(0, true); a < n;) {
    const int b = bits.next(a + 1, false);
    ramp(a);
    for (int x = a; x < b; ++x) out[x] = 0.0f;
    // A shadow at column 0 may continue the one before it.
    prev_run = a == prev_end ? prev_run + (b - a) : b - a;
    prev_end = b;
    a = bits.next(b, true);
  }
  ramp(n);
}

}  // namespace

void wind_shadow(const terrain::HeightField& h, HeightRange range, double drop_per_column,
                 double max_columns, ShadowMap& shadow) {
  const int n = h.width(), rows = h.height();
  assert(drop_per_column > 0);
  shadow.resize(h.size());
  // Reaches are kept in 15 bits.
  const int limit = static_cast<int>(
      std::min<double>({static_cast<double>(n), std::ceil(max_columns) + 1, 32767.0}));
  const Span span{warm_up_columns(n, range, drop_per_column), limit};
  const std::array<Run, 3> path = runs(n, span);
  // Blocks of kLineBlock rows side by side; a short last block repeats its
  // last row.
  const int blocks = (rows + kLineBlock - 1) / kLineBlock;
  tbb::parallel_for(
      0, blocks,
      [&](int block) {
        const int j0 = block * kLineBlock, j1 = std::min(rows, j0 + kLineBlock);
        thread_local std::vector<std::int32_t> flags;
        flags.resize(static_cast<std::size_t>(n + span.ahead) * kLineBlock);
        std::array<std::int32_t, kLineBlock> first_row;
        for (int k = 0; k < kLineBlock; ++k) first_row[k] = std::min(j0 + k, j1 - 1);
        mark_shadowed(h.data(), n, drop_per_column, path, first_row.data(), flags.data());
        measure_reach(n, limit, span, j0, j1, flags, shadow);
      },
      tbb::simple_partitioner());
}

void line_recovery(const std::uint16_t* line, int width, double ratio, float* out) {
  assert(ratio > 0 && width > 0);
  recover_line(line, width, ratio, out);
}

void shadow_recovery(const ShadowMap& shadow, int width, double ratio,
                     std::vector<float>& recovery) {
  assert(ratio > 0 && width > 0);
  const int n = width, lines = static_cast<int>(shadow.size() / static_cast<std::size_t>(n));
  recovery.resize(shadow.size());
  tbb::parallel_for(
      0, lines,
      [&](int j) {
        const std::size_t at = static_cast<std::size_t>(j) * n;
        recover_line(&shadow[at], n, ratio, &recovery[at]);
      },
      tbb::simple_partitioner());
}

}  // namespace drift::dunes
