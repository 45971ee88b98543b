// A height field simplified to a maximum vertical error: a right-triangulated
// irregular network (RTIN; Evans, Kirkpatrick and Townsend 2001, "Right-
// triangulated irregular networks", Algorithmica 30; the array layout of
// Mapbox's Martini). Triangles are the halves of a binary tree of right
// isosceles triangles over the grid; a triangle is split at its hypotenuse's
// midpoint, and the midpoint's error carries the errors of every triangle
// below it, so both triangles sharing a hypotenuse split together and the
// mesh has no cracks (no vertex in the middle of another triangle's edge).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "terrain/grid.h"

namespace drift::terrain {

// A triangle of grid points: (column, row) of its three corners, any winding.
using GridTriangle = std::array<std::array<int, 2>, 3>;

struct RtinMesh {
  std::vector<GridTriangle> triangles;
  // The largest |height - the triangle's plane| over every grid cell centre
  // the kept triangles cover (0 when every cell is a vertex): <= max_error.
  double max_error = 0.0;
  // The distinct grid points the triangles use.
  std::uint64_t vertices = 0;
};

// The fewest-levels RTIN whose triangles all lie within `max_error` metres
// (vertically) of every cell centre they cover. Unlike Martini's midpoint
// error, a triangle's error here is measured at every cell it covers, so the
// bound holds exactly at every cell, not only at the midpoints. A grid of any
// size is laid into the smallest 2^k + 1 square; triangles reaching past the
// grid, or over a nodata (NaN) cell, are split down to single cells, and the
// halves of a cell with a nodata or outside corner are left out (the full
// mesh leaves out the whole cell). Throws drift::Error for a negative
// max_error or a grid smaller than 2 x 2.
// `before_list`, if given, is called once the tree is decided and before the
// triangle list is allocated, with the number of distinct vertices and of
// triangles the mesh will have (so that a memory check counts the mesh the
// bound keeps, not every triangle at worst); it may throw to stop.
using RtinSizeCheck = std::function<void(std::uint64_t vertices, std::uint64_t triangles)>;
RtinMesh rtin_triangles(const HeightField& heights, double max_error,
                        const RtinSizeCheck& before_list = {});

}  // namespace drift::terrain
