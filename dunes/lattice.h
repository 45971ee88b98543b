// Neighbours on the wind lattice (dunes/wind_frame.h): rows close on
// themselves, and past the last row, row 0 goes on `shift` columns back
// (point (x, row + K) is point (x - shift, row)).
#pragma once

#include <algorithm>
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

// The rows -1 to K of a lattice of K rows, as sweeps read them: its own,
// and past either edge the wrapped row turned by the shift (a rotation),
// worked out once.
class LatticeRows {
 public:
  LatticeRows(const terrain::HeightField& h, int shift) : h_(h) {
    before_ = turned(h.height() - 1, -1, shift);
    after_ = turned(0, 1, shift);
  }
  const float* operator[](int row) const {
    if (row < 0) return before_.data();
    if (row >= h_.height()) return after_.data();
    return &h_(0, row);
  }

 private:
  // Row `source` a lap of rows away (laps = +-1): point x is source point
  // x - laps * shift, wrapped.
  std::vector<float> turned(int source, int laps, int shift) const {
    const int w = h_.width();
    const int offset = wrap_index(laps * (shift % w), w);
    const float* row = &h_(0, source);
    std::vector<float> out(static_cast<std::size_t>(w));
    std::copy(row + (w - offset), row + w, out.begin());
    std::copy(row, row + (w - offset), out.begin() + offset);
    return out;
  }
  const terrain::HeightField& h_;
  std::vector<float> before_, after_;
};

}  // namespace drift::dunes
