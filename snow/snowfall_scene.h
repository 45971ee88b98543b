// The scene snow falls on, in a local frame: the ground height field and the
// objects (triangle meshes) standing on it. Local coordinates keep floats small:
// the origin is the DEM's central cell at the lowest ground height.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "terrain/grid.h"
#include "terrain/mesh.h"

namespace drift::snow {

struct SnowScene {
  terrain::Grid<float> ground;        // local heights; nodata filled with the lowest height
  double x0 = 0, y0 = 0;              // local position of the centre of cell (0, 0)
  double dx = 1, dy = 1;              // cell sizes (m); columns run east, rows south
  Eigen::Vector3d origin{0, 0, 0};    // CRS position of the local origin
  std::vector<terrain::Mesh> meshes;  // objects in the local frame, refined
  float ground_lo = 0, ground_hi = 0;

  double col_of(double x) const { return (x - x0) / dx; }
  double row_of(double y) const { return (y0 - y) / dy; }
  Eigen::Vector3d cell_point(int col, int row) const {
    return {x0 + col * dx, y0 - row * dy, ground(col, row)};
  }
  // Gradient and unit normal of the ground by central differences (one-sided
  // at the edges; terrain/derivatives.h).
  Eigen::Vector2d ground_gradient(int col, int row) const;
  Eigen::Vector3d ground_normal(int col, int row) const;
};

// Throws drift::Error for a raster that is not north-up with positive cell sizes,
// smaller than 2 x 2, or all nodata. Object meshes are refined to max_edge (m;
// 0 keeps them).
SnowScene make_snow_scene(const terrain::HeightField& ground,
                          const std::vector<terrain::PlacedMesh>& objects, double max_edge);

}  // namespace drift::snow
