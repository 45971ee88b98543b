#include "dunes/height_range.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <initializer_list>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace drift::dunes {

namespace {

// The range of v[begin, end), merged into m.
HeightRange block_range(const float* v, std::size_t begin, std::size_t end, HeightRange m) {
  std::size_t i = begin;
#if defined(__SSE2__)
  // Four lanes per bound (GCC does not vectorise a float min/max reduction
  // without -ffast-math, which would let it reassociate sums elsewhere).
  // minps/maxps on numbers are exact, so the result is the scalar one.
  __m128 lo = _mm_set1_ps(m.lo), hi = _mm_set1_ps(m.hi);
  for (; i + 4 <= end; i += 4) {
    const __m128 x = _mm_loadu_ps(v + i);
    lo = _mm_min_ps(lo, x);
    hi = _mm_max_ps(hi, x);
  }
  alignas(16) float l[4], h[4];
  _mm_store_ps(l, lo);
  _mm_store_ps(h, hi);
  m = {std::min({l[0], l[1], l[2], l[3]}), std::max({h[0], h[1], h[2], h[3]})};
#endif
  for (; i < end; ++i) m = {std::min(m.lo, v[i]), std::max(m.hi, v[i])};
  return m;
}

}  // namespace

HeightRange height_range(const terrain::HeightField& h) {
  const float* v = h.data();
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, h.size(), std::size_t{1} << 16),
      HeightRange{1e30f, -1e30f},
      [v](const tbb::blocked_range<std::size_t>& r, HeightRange m) {
        return block_range(v, r.begin(), r.end(), m);
      },
      [](HeightRange a, HeightRange b) {
        return HeightRange{std::min(a.lo, b.lo), std::max(a.hi, b.hi)};
      });
}

}  // namespace drift::dunes
