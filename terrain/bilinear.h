// Bilinear interpolation on a grid of values: the one formula every module
// uses to read a raster, a vertex buffer or a texture between its samples.
//
// The blend is written once, in one order of operations, so that callers in
// float and in double, on scalars and on Eigen vectors, round alike:
//   (1 - ty) ((1 - tx) v00 + tx v10) + ty ((1 - tx) v01 + tx v11).
#pragma once

#include <algorithm>
#include <type_traits>

#include "terrain/grid.h"

namespace drift::terrain {

// The blend of four corner values at fractions (tx, ty) in [0, 1]: v00 at
// (0, 0), v10 at (1, 0), v01 at (0, 1), v11 at (1, 1). T is a scalar or an
// Eigen vector; S the scalar type of the weights.
template <class T, class S>
T bilinear_blend(const T& v00, const T& v10, const T& v01, const T& v11, S tx, S ty) {
  return (1 - ty) * ((1 - tx) * v00 + tx * v10) + ty * ((1 - tx) * v01 + tx * v11);
}

// A fractional grid position split into its cell and the fractions inside it.
template <class S>
struct BilinearCell {
  int x0 = 0, y0 = 0;  // the cell's first corner
  int x1 = 0, y1 = 0;  // the opposite corner (x0 + 1, y0 + 1, or x0, y0 on a 1-wide grid)
  S tx = 0, ty = 0;    // fractions from (x0, y0), in [0, 1]
};

// The cell of position (x, y) on a `width` x `height` grid of samples at whole
// coordinates, the position clamped to the grid first: beyond the border the
// edge samples hold.
template <class S>
BilinearCell<S> clamped_cell(S x, S y, int width, int height) {
  x = std::clamp(x, S(0), static_cast<S>(width - 1));
  y = std::clamp(y, S(0), static_cast<S>(height - 1));
  BilinearCell<S> c;
  c.x0 = std::min(static_cast<int>(x), std::max(width - 2, 0));
  c.y0 = std::min(static_cast<int>(y), std::max(height - 2, 0));
  c.x1 = std::min(c.x0 + 1, width - 1);
  c.y1 = std::min(c.y0 + 1, height - 1);
  c.tx = x - c.x0;
  c.ty = y - c.y0;
  return c;
}

// The bilinear value at (x, y) of samples read through `at(x, row)`, clamped
// to the grid (clamped_cell). The weights are of type S; `at`'s values are
// blended as they come (give them in S for a blend in S's precision).
template <class S, class At>
auto bilinear_clamped(const At& at, int width, int height, S x, S y) {
  using T = std::decay_t<decltype(at(0, 0))>;
  const BilinearCell<S> c = clamped_cell(x, y, width, height);
  return bilinear_blend<T, S>(at(c.x0, c.y0), at(c.x1, c.y0), at(c.x0, c.y1), at(c.x1, c.y1), c.tx,
                              c.ty);
}

// The bilinear height of `grid` at fractional (col, row), clamped to the grid,
// blended in double and rounded to float.
inline float bilinear_clamped(const Grid<float>& grid, double col, double row) {
  const auto at = [&](int x, int r) { return static_cast<double>(grid(x, r)); };
  return static_cast<float>(bilinear_clamped(at, grid.width(), grid.height(), col, row));
}

}  // namespace drift::terrain
