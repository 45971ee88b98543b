// Test terrain from a formula: the one helper the test suites share for it.
#pragma once

#include <cmath>
#include <cstring>

#include "terrain/grid.h"

namespace drift::testing {

// A square DEM of n x n cells of `cell` metres (local georeference, NW corner
// at (0, 0)) with z = f(x, y) at each cell centre, where x = (col + offset)
// cell east and y = -(row + offset) cell north: offset 0.5 measures from the
// NW corner, -(n - 1) / 2 from the grid's centre.
template <class F>
terrain::HeightField dem_from(int n, double cell, double offset, F f) {
  terrain::HeightField dem(n, n, 0.0f, terrain::local_georeference(cell));
  for (int row = 0; row < n; ++row)
    for (int x = 0; x < n; ++x)
      dem(x, row) = static_cast<float>(f((x + offset) * cell, -((row + offset) * cell)));
  return dem;
}

// Cells whose bits differ (NaN equals NaN), or -1 for another shape: block
// by block against one pass, bit for bit.
inline long differing_cells(const terrain::HeightField& a, const terrain::HeightField& b) {
  if (a.width() != b.width() || a.height() != b.height()) return -1;
  long n = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    n += std::memcmp(&a.values()[i], &b.values()[i], sizeof(float)) != 0;
  return n;
}

// A flat n x n ground at height z, `cell` metres a cell, placed at UTM-sized
// coordinates (NW corner at 600000 E, 4000000 N) as a user's ground would be.
inline terrain::HeightField flat_utm_ground(int n, float z, double cell) {
  terrain::HeightField g(n, n, z, terrain::local_georeference(cell));
  g.geo().geotransform[0] = 600000.0;
  g.geo().geotransform[3] = 4000000.0;
  return g;
}

// The snowfall benchmark's mountains (tests/bench/snowfall_bench.cpp), whose
// north-west corner the stabilisation tests settle: n x n cells of 1 m,
// long slopes steeper than repose with ledges and hollows between.
inline terrain::HeightField snowfall_mountains(int n) {
  terrain::HeightField g(n, n, 0.0f, terrain::local_georeference(1.0));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      g(x, y) = static_cast<float>(200 * std::sin(x / 300.0) * std::cos(y / 450.0) +
                                   60 * std::sin(x / 70.0 + y / 90.0) +
                                   10 * std::sin(x / 13.0) * std::cos(y / 17.0));
  return g;
}

}  // namespace drift::testing
