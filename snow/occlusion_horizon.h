// The height-field path of the occlusion test: instead of rasterising the DEM's
// triangles into a depth map (OSMesa, terrain/offscreen/osmesa_depth_renderer.h),
// sweep the grid line by line from the side the snow comes from, carrying the
// "shadow surface"
//   S(p) = max(h(p), S(p + s * horizontal) - s * tan(elevation)),
// the highest the terrain upstream reaches along the ray through p; S at the
// upstream point is interpolated linearly between the two cells the ray crosses.
// A point at height z is seen from the source when z >= S. O(cells) per
// direction, no rasteriser, no depth bias: the same answers as the depth map up to
// the interpolation of the surface between cells (tests/snow check they agree).
#pragma once

#include <Eigen/Core>

#include "terrain/bilinear.h"
#include "terrain/grid.h"

namespace drift::snow {

// S for one direction. When the sweep runs along columns the surface is kept
// transposed (width = the ground's rows), saving a transposition per direction;
// read it through at() and bilinear_at().
struct ShadowSurface {
  terrain::Grid<float> s;
  bool transposed = false;
  float at(int col, int row) const { return transposed ? s(row, col) : s(col, row); }
  float bilinear_at(double col, double row) const {
    return transposed ? terrain::bilinear_clamped(s, row, col)
                      : terrain::bilinear_clamped(s, col, row);
  }
};

// Sweeps one height field for many directions; the transposed heights, needed for
// directions closer to east-west than north-south, are made once.
class HorizonSweeper {
 public:
  // heights: local frame (m); dx, dy: cell sizes (m), columns east, rows south.
  HorizonSweeper(const terrain::Grid<float>& heights, double dx, double dy)
      : heights_(heights), dx_(dx), dy_(dy) {}
  // toward_source: unit, z > 0. Straight-down fall gives S = heights.
  ShadowSurface shadow(const Eigen::Vector3d& toward_source);

 private:
  const terrain::Grid<float>& heights_;
  double dx_, dy_;
  terrain::Grid<float> transposed_;
};

}  // namespace drift::snow
