// Surface derivatives of a height field: gradient, unit normals, slope and
// aspect, and a multi-resolution pyramid.
//
// The gradient is Horn's (1981) 3x3 weighted difference, the default of
// `gdaldem slope` and `gdaldem aspect`, so our rasters agree with GDAL's on the
// same DEM (tests/terrain/derivatives_test.cpp checks it cell by cell). Cell
// sizes come from the georeference (metres for a projected DEM); heights are in
// the same unit. Every valid cell gets a value: at the border the missing
// neighbours are extrapolated linearly and next to nodata they take the centre
// cell's height, as `gdaldem -compute_edges` does; nodata cells stay NaN.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "terrain/grid.h"

namespace drift::terrain {

// dz/dx (east) and dz/dy (north) of a cell, in height units per metre.
struct Gradient {
  float dzdx = 0.0f;
  float dzdy = 0.0f;
};

// Horn (1981) from a 3x3 neighbourhood  a b c / d e f / g h i  (row a b c to
// the north) of cells `ew` by `ns` metres.
inline Gradient horn_3x3(float a, float b, float c, float d, float f, float g, float h, float i,
                         float ew, float ns) {
  return {((c + 2 * f + i) - (a + 2 * d + g)) / (8 * ew),
          ((a + 2 * b + c) - (g + 2 * h + i)) / (8 * ns)};
}

// Horn's gradient at cell (x, row); NaN components for a nodata cell.
Gradient horn_gradient(const HeightField& dem, int x, int row);

// The same for any north-up grid of `width` x `height` heights read through
// `z_at(x, row)` (NaN for nodata), with cells `ew` by `ns` metres: for callers
// that keep heights in their own layout (the renderer's vertex buffer).
template <class HeightAt>
Gradient horn_gradient(const HeightAt& z_at, int width, int height, float ew, float ns, int x,
                       int row);

// Central differences at cell (x, row) of a `width` x `height` grid read
// through `z_at(x, row)`, cells `ew` by `ns` metres: (dz/dx east, dz/dy north),
// one-sided at the border. The snowfall's ground normals (paper 003 needs only
// n . w per cell, and the plain 4-neighbour stencil follows the grid's facets);
// rasters that must agree with gdaldem use Horn's gradient above.
template <class HeightAt>
Eigen::Vector2d central_gradient(const HeightAt& z_at, int width, int height, double ew, double ns,
                                 int x, int row) {
  const int xl = std::max(x - 1, 0), xr = std::min(x + 1, width - 1);
  const int rn = std::max(row - 1, 0), rs = std::min(row + 1, height - 1);
  return {(z_at(xr, row) - z_at(xl, row)) / ((xr - xl) * ew),
          (z_at(x, rn) - z_at(x, rs)) / ((rs - rn) * ns)};
}

// The unit upward normal (x east, y north, z up) of a surface whose gradient is
// `g` (dz/dx, dz/dy).
inline Eigen::Vector3d normal_from_gradient(const Eigen::Vector2d& g) {
  return Eigen::Vector3d(-g.x(), -g.y(), 1.0).normalized();
}

// Per-cell gradient, computed in parallel.
Grid<Gradient> gradient(const HeightField& dem);

// Unit upward normals (x east, y north, z up) of the surface z = dem * z_scale.
Grid<Eigen::Vector3f> normals(const HeightField& dem, float z_scale = 1.0f);

// Slope in degrees from horizontal, [0, 90). As `gdaldem slope`.
HeightField slope_degrees(const HeightField& dem);

// Aspect: the compass direction the slope faces (downhill), degrees clockwise
// from north in [0, 360). Flat cells have no aspect and are NaN (gdaldem writes
// its nodata value -9999 there). As `gdaldem aspect` on a north-up raster.
HeightField aspect_degrees(const HeightField& dem);

// A resolution pyramid: level 0 is `dem`, each next level halves both sizes
// (rounding up) by averaging the valid cells of each 2x2 block (NaN where all
// four are nodata), with the georeference's cell size doubled. Stops at a
// level whose longer side is at most `min_size` cells.
std::vector<HeightField> pyramid(const HeightField& dem, int min_size = 1);

// One pyramid step (exposed for tests and for other grids of floats).
HeightField halve(const HeightField& grid);

template <class HeightAt>
Gradient horn_gradient(const HeightAt& z_at, int width, int height, float ew, float ns, int x,
                       int row) {
  const float centre = z_at(x, row);
  if (std::isnan(centre)) return {NAN, NAN};
  // z(dx, dr): the neighbour's height. Beyond the border it is extrapolated
  // linearly from the two nearest cells in its column (rows beyond) or row
  // (columns beyond), the column clamped first; a nodata neighbour, or one
  // extrapolated from nodata, takes the centre's height. These are exactly
  // gdaldem's -compute_edges rules, so the results agree at the border too.
  auto valid_or_centre = [&](float v) { return std::isnan(v) ? centre : v; };
  auto z = [&](int dx, int dr) {
    int xx = x + dx;
    const int rr = row + dr;
    if (rr < 0 || rr >= height) {
      xx = std::clamp(xx, 0, width - 1);
      const int edge = rr < 0 ? 0 : height - 1;
      const int inner = rr < 0 ? std::min(1, height - 1) : std::max(height - 2, 0);
      return valid_or_centre(2 * z_at(xx, edge) - z_at(xx, inner));
    }
    if (xx < 0 || xx >= width) {
      const int edge = xx < 0 ? 0 : width - 1;
      const int inner = xx < 0 ? std::min(1, width - 1) : std::max(width - 2, 0);
      return valid_or_centre(2 * z_at(edge, rr) - z_at(inner, rr));
    }
    return valid_or_centre(z_at(xx, rr));
  };
  return horn_3x3(z(-1, -1), z(0, -1), z(1, -1), z(-1, 0), z(1, 0), z(-1, 1), z(0, 1), z(1, 1), ew,
                  ns);
}

}  // namespace drift::terrain
