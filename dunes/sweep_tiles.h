// Fixed tiles of a field for parallel sweeps: blocks of rows by strips of
// columns. The partition depends only on the field's size, never on the
// number of threads, so neither does any bit of a sweep; and a strip's
// per-row scratch stays in the L1 cache however long the rows (a wind
// lattice's rows are up to tens of thousands of points, dunes/wind_frame.h).
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>

namespace drift::dunes {

// Rows [first_row, end_row) by columns [x0, x1).
struct Tile {
  int first_row, end_row, x0, x1;
};

inline constexpr int kTileRows = 16;
inline constexpr int kTileColumns = 1024;  // at most; strips of a row are near equal

// Calls fn(tile) for every tile of a width x rows field, in parallel.
template <class Fn>
void for_tiles(int width, int rows, Fn fn) {
  const int strips = (width + kTileColumns - 1) / kTileColumns;
  const int blocks = (rows + kTileRows - 1) / kTileRows;
  tbb::parallel_for(
      0, blocks * strips,
      [&](int task) {
        const int block = task / strips, strip = task % strips;
        const auto column = [&](int k) {
          return static_cast<int>(static_cast<long long>(width) * k / strips);
        };
        fn(Tile{block * kTileRows, std::min(rows, (block + 1) * kTileRows), column(strip),
                column(strip + 1)});
      },
      tbb::simple_partitioner());
}

// The columns of a strip [x0, x1) of a row `width` points long, whose
// columns wrap, with both neighbours inside the row: [begin, end).
struct InnerColumns {
  int begin, end;
};
inline InnerColumns inner_columns(int x0, int x1, int width) {
  return {std::max(x0, 1), std::min(x1, width - 1)};
}

// Calls cell(x, west, east) for the strip's wrapped columns, 0 and width -
// 1, if it has them, with their wrapped neighbours.
template <class Cell>
void for_wrapped_columns(int x0, int x1, int width, Cell cell) {
  if (x0 == 0) cell(0, width - 1, 1);
  if (x1 == width) cell(width - 1, width - 2, 0);
}

// Calls cell(x, x - 1, x + 1) for every column of the tile's strip: the
// inner columns first, in a loop with no wrapping test, then the wrapped
// ones. (A kernel that stores through `restrict` pointers writes the inner
// loop itself: a lambda's capture by reference loses `restrict`, and GCC
// then does not vectorise.)
template <class Cell>
void for_strip_columns(const Tile& t, int width, Cell cell) {
  const InnerColumns inner = inner_columns(t.x0, t.x1, width);
  for (int x = inner.begin; x < inner.end; ++x) cell(x, x - 1, x + 1);
  for_wrapped_columns(t.x0, t.x1, width, cell);
}

}  // namespace drift::dunes
