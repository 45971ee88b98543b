// The height-field path of the occlusion test: instead of rasterising the DEM's
// triangles into a depth map (OSMesa, occlusion_osmesa.h), sweep the grid line by
// line from the side the snow comes from, carrying the "shadow surface"
//   S(p) = max(h(p), S(p + s * horizontal) - s * tan(elevation)),
// the highest the terrain upstream reaches along the ray through p; S at the
// upstream point is interpolated linearly between the two cells the ray crosses.
// A point at height z is seen from the source when z >= S. O(cells) per
// direction, no rasteriser, no depth bias: the same answers as the depth map up to
// the interpolation of the surface between cells (tests/snow check they agree).
#pragma once

#include <Eigen/Core>

#include "terrain/grid.h"

namespace drift::snow {

// heights: local frame (m); dx, dy: cell sizes (m), columns east, rows south.
// toward_source: unit, z > 0. Straight-down fall gives S = heights.
terrain::Grid<float> horizon_shadow_surface(const terrain::Grid<float>& heights, double dx,
                                            double dy, const Eigen::Vector3d& toward_source);

// Bilinear S at fractional (col, row) clamped to the grid.
float bilinear(const terrain::Grid<float>& g, double col, double row);

}  // namespace drift::snow
