// Neighbours on the wind lattice (dunes/wind_frame.h): rows close on
// themselves, and past the last row, row 0 goes on `shift` columns back
// (point (x, row + K) is point (x - shift, row)).
#pragma once

#include <vector>

#include "terrain/grid.h"

namespace drift::dunes {

inline int wrap_index(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

// a / n rounded down (n > 0), for negative a too.
inline long long floor_div(long long a, long long n) {
  return a >= 0 ? a / n : -((-a + n - 1) / n);
}

// The height of lattice point (x, row) for any x and row: a row past either
// edge is the wrapped row `shift` columns back per lap of rows.
inline float lattice_at(const terrain::HeightField& h, long long x, long long row, int shift) {
  const long long laps = floor_div(row, h.height());
  const long long column = x - laps * shift;
  const long long wrapped = column % h.width();
  return h(static_cast<int>(wrapped < 0 ? wrapped + h.width() : wrapped),
           static_cast<int>(row - laps * h.height()));
}

// The heights of lattice row `row` (any integer): the row itself if it lies
// in the field, else the wrapped row turned by the shift into `buffer`.
inline const float* lattice_row(const terrain::HeightField& h, int row, int shift,
                                std::vector<float>& buffer) {
  if (row >= 0 && row < h.height()) return &h(0, row);
  const int w = h.width();
  buffer.resize(static_cast<std::size_t>(w));
  for (int x = 0; x < w; ++x) buffer[x] = lattice_at(h, x, row, shift);
  return buffer.data();
}

}  // namespace drift::dunes
