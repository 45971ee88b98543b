// Neighbours on the wind lattice (dunes/wind_frame.h): rows are periodic,
// and past the last column row j goes on as row j + shear from column 0.
#pragma once

#include <array>

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

// The height of lattice point (x, row) for any x in [-n, 2n) and any row:
// a column past either edge is the wrapped column on the row a lap on or back.
inline float lattice_at(const terrain::HeightField& h, int x, int row, int shear) {
  const int n = h.width();
  const int laps = x < 0 ? -1 : (x >= n ? 1 : 0);
  return h(x - laps * n, wrap_index(row + laps * shear, h.height()));
}

// The 3 x 3 heights around lattice point (x, row): [0] the row above
// (columns x - 1, x, x + 1), [1] the row, [2] the row below.
using Neighbourhood = std::array<std::array<float, 3>, 3>;
inline Neighbourhood neighbourhood(const terrain::HeightField& h, int x, int row, int shear) {
  Neighbourhood out;
  for (int dr = -1; dr <= 1; ++dr)
    for (int dx = -1; dx <= 1; ++dx) out[dr + 1][dx + 1] = lattice_at(h, x + dx, row + dr, shear);
  return out;
}

}  // namespace drift::dunes
