#include "dunes/wind_shadow.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstring>
#include <numeric>
#include <span>
#include <type_traits>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "dunes/height_range.h"
#include "dunes/lattice.h"
#include "terrain/simd.h"

namespace drift::dunes {

namespace {

// Lines per task, swept side by side: independent recurrences overlap their
// latency, and 4 rows a power-of-two stride apart still fit the ways of one
// L1 set (16 did not). A fixed partition, and lines do not interact: the
// same bits for any thread count.
constexpr int kLineBlock = 4;

// The columns a line is followed: `warm_up` before column 0 (no sample
// further upwind can still cast a shadow, as the shadow line falls by more
// than the field's height range over them), then the field's width
// and `ahead` more for the distances. For the lift's recovery on sheared
// lines, which do not close on themselves after a lap, also `history`
// columns before 0 whose shadows are followed (after their own warm-up).
struct Span {
  int warm_up, ahead, history = 0;
  int before() const { return warm_up + history; }
};

// Where the lift's recovery stands on a line at column 0: the samples since
// the last shadow before it and that shadow's length.
struct LineStart {
  int since = 1 << 29, run = 0;  // no shadow seen
};

// The columns a line is followed, unwrapped x in [-span.before(),
// n + span.ahead), a lap of the field at a time: in lap `l` (x in
// [l n, (l + 1) n)) the line reads column x - l n of the row l shear on
// (modulo the field's rows). Along x every lap reads the row itself.
struct Lap {
  int begin, end;     // unwrapped columns
  int column_offset;  // -l n
  int row_shift;      // l shear, wrapped
};

std::vector<Lap> laps(int n, int rows, int shear, Span span) {
  std::vector<Lap> out;
  const int end = n + span.ahead;
  for (int x = -span.before(); x < end;) {
    const long long lap = floor_div(x, n);
    const int lap_end = static_cast<int>(std::min<long long>((lap + 1) * n, end));
    out.push_back({x, lap_end, static_cast<int>(-lap * n),
                   wrap_index(static_cast<int>(lap * shear % rows), rows)});
    x = lap_end;
  }
  return out;
}

// A block's lines side by side in the lanes of one vector (GCC's vector
// extensions: two SSE2 registers in the baseline build, one AVX2 register
// in its twin; the same IEEE operation in every lane either way).
using LineDoubles = double __attribute__((vector_size(kLineBlock * sizeof(double))));
using LineInts = std::int32_t __attribute__((vector_size(kLineBlock * sizeof(std::int32_t))));

// Shadow flags of a block of kLineBlock lines at columns [0, n + ahead):
// each sample below the shadow line cast by the samples upwind of it, at
// flags[x * kLineBlock + lane]. Lane k follows line first_row[k] (a short
// last block repeats its last line), lap by lap (`laps`, `count` of them).
// With `starts`, also where the recovery stands at column 0 on each line,
// from the shadows of the `history` columns before it.
DRIFT_SIMD_KERNEL void mark_shadowed_kernel(const float* data, int n, int rows,
                                            double drop_per_column, int history, const Lap* laps,
                                            int count, const std::int32_t* first_row,
                                            std::int32_t* flags, LineStart* starts) {
  static_assert(kLineBlock == 4, "the lanes below are written out for 4 lines");
  LineDoubles carried = {-1e300, -1e300, -1e300, -1e300};
  LineInts since = LineInts{} + (1 << 29), run = LineInts{};  // no shadow seen
  for (const Lap& lap : std::span(laps, static_cast<std::size_t>(count))) {
    std::array<const float*, kLineBlock> line_row;
    for (int k = 0; k < kLineBlock; ++k) {
      const int row = first_row[k] + lap.row_shift;
      line_row[k] = data + static_cast<std::size_t>(row < rows ? row : row - rows) * n;
    }
    for (int x = lap.begin; x < lap.end; ++x) {
      const int c = x + lap.column_offset;
      const LineDoubles v = {line_row[0][c], line_row[1][c], line_row[2][c], line_row[3][c]};
      const LineDoubles line = carried - drop_per_column;
      const LineInts shadow = __builtin_convertvector(v < line, LineInts);  // -1 or 0
      if (x >= 0) {
        const LineInts flag = shadow & 1;
        std::memcpy(flags + static_cast<std::size_t>(x) * kLineBlock, &flag, sizeof flag);
      } else if (x >= -history) {
        run = shadow != 0 ? (since == 0 ? run + 1 : LineInts{} + 1) : run;
        since = shadow != 0 ? LineInts{} : since + 1;
      }
      carried = line < v ? v : line;  // std::max(line, v)
    }
  }
  for (int k = 0; starts && k < kLineBlock; ++k) starts[k] = {since[k], run[k]};
}
DRIFT_SIMD_TWINS(mark_shadowed, mark_shadowed_kernel,
                 (const float* data, int n, int rows, double drop_per_column, int history,
                  const Lap* laps, int count, const std::int32_t* first_row, std::int32_t* flags,
                  LineStart* starts),
                 (data, n, rows, drop_per_column, history, laps, count, first_row, flags, starts))

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

// Columns before column 0 that a line must be followed for.
// Past that, a line has come round to its own start: after a lap for a row,
// after rows / gcd(shear, rows) laps for a sheared line. Shadows longer than
// 4 laps of the field (a shadow angle of a small fraction of a degree) are
// cut there, which keeps the path followed (and the recovery's history, a
// multiple of it) within a few laps rather than up to a lap per row.
int warm_up_columns(const terrain::HeightField& h, int shear, double drop_per_column) {
  const HeightRange range = height_range(h);
  const double columns = (static_cast<double>(range.hi) - range.lo) / drop_per_column + 2;
  constexpr int kMaxLaps = 4;
  const int laps =
      shear == 0 ? 1 : std::min(kMaxLaps, h.height() / std::gcd(std::abs(shear), h.height()));
  return static_cast<int>(std::min<double>(static_cast<double>(h.width()) * laps, columns));
}

// A line's shadow flags as bits (bit x % 64 of word x / 64), so that runs
// in and out of shadow are found a word at a time: a line has some thirty
// shadows, mostly a few samples long.
class ShadowBits {
 public:
  // Lines of up to 16384 samples (the grid's limit) in a fixed array: no
  // allocation per line.
  ShadowBits(const std::uint16_t* s, int n) : n_(n), count_((n + 63) / 64) {
    assert(count_ <= static_cast<int>(words_.size()));
    std::fill_n(words_.begin(), count_, std::uint64_t{0});
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
  int n_, count_;
  std::array<std::uint64_t, 256> words_;
};

// The lift's recovery along one line of n samples of the shadow map (see
// shadow_recovery()), from where it stands at column 0: `start`, or if null
// the line's own end (a line that closes on itself after a lap).
void recover_line(const std::uint16_t* s, int n, double ratio, const LineStart* start, float* out) {
  // The previous shadow: where it ended (the first sample past it, <= 0 for
  // one before column 0) and its length (0: none).
  int prev_end = 0, prev_run = 0;
  if (start) {
    prev_end = -start->since;
    prev_run = start->run;
  } else {
    // The line's last shadowed run, counted back from its end.
    int last = n - 1;
    while (last >= 0 && !shadowed(s[last])) --last;
    for (int x = last; x >= 0 && shadowed(s[x]); --x) ++prev_run;
    prev_end = last + 1 - n;
  }
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

void wind_shadow(const terrain::HeightField& h, int shear, double drop_per_cell, double max_columns,
                 ShadowMap& shadow, double recovery_ratio, std::vector<float>* recovery) {
  const int n = h.width(), rows = h.height();
  assert(std::abs(shear) <= n && n <= 32767 && drop_per_cell > 0);
  const double rows_per_column = static_cast<double>(shear) / n;
  shadow.resize(h.size());
  if (recovery) recovery->resize(h.size());
  // A column step is sqrt(1 + t^2) cells along the wind.
  const double drop_per_column = drop_per_cell * std::sqrt(1.0 + rows_per_column * rows_per_column);
  const int limit = static_cast<int>(std::min<double>(n, std::ceil(max_columns) + 1));
  Span span{warm_up_columns(h, shear, drop_per_column), limit};
  // Rows close on themselves after a lap, so the recovery at column 0 can
  // start from a row's own end. Sheared lines do not: follow each back over
  // the history its recovery needs, the ramp after the longest shadow
  // (no longer than the warm-up) and that shadow itself.
  const bool sheared = shear != 0;
  if (recovery && sheared) {
    span.history = static_cast<int>(std::ceil((recovery_ratio + 1.0) * span.warm_up)) + 1;
  }
  const std::vector<Lap> path = laps(n, rows, shear, span);
  // Blocks of kLineBlock lines side by side; a short last block repeats its
  // last line.
  const int blocks = (rows + kLineBlock - 1) / kLineBlock;
  tbb::parallel_for(
      0, blocks,
      [&](int block) {
        const int j0 = block * kLineBlock, j1 = std::min(rows, j0 + kLineBlock);
        thread_local std::vector<std::int32_t> flags;
        flags.resize(static_cast<std::size_t>(n + span.ahead) * kLineBlock);
        std::array<std::int32_t, kLineBlock> first_row;
        for (int k = 0; k < kLineBlock; ++k) first_row[k] = std::min(j0 + k, j1 - 1);
        std::array<LineStart, kLineBlock> starts;
        LineStart* starts_at = recovery && sheared ? starts.data() : nullptr;
        mark_shadowed(h.data(), n, rows, drop_per_column, span.history, path.data(),
                      static_cast<int>(path.size()), first_row.data(), flags.data(), starts_at);
        measure_reach(n, limit, span, j0, j1, flags, shadow);
        // The recovery while the block's lines of the map are at hand in
        // cache, rather than in a pass of its own.
        for (int j = j0; recovery && j < j1; ++j) {
          const std::size_t at = static_cast<std::size_t>(j) * n;
          recover_line(&shadow[at], n, recovery_ratio, starts_at ? starts_at + (j - j0) : nullptr,
                       &(*recovery)[at]);
        }
      },
      tbb::simple_partitioner());
}

void line_recovery(const std::uint16_t* line, int width, double ratio, float* out) {
  assert(ratio > 0 && width > 0);
  recover_line(line, width, ratio, nullptr, out);
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
        recover_line(&shadow[at], n, ratio, nullptr, &recovery[at]);
      },
      tbb::simple_partitioner());
}

}  // namespace drift::dunes
