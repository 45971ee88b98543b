// An object's triangles in the grid's cell space, placed at a pose or swept
// between two (paper 000, 3.3, figs. 2-3).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "terrain/grid.h"
#include "terrain/marks/object_bottom.h"
#include "terrain/marks/trajectory.h"
#include "terrain/mesh.h"

namespace drift::marks {

// Cell space of a north-up grid: column = (x - x0) / dx, row = (y0 - y) / dy,
// (x0, y0) the centre of cell (0, 0) in the ground's CRS.
struct GridFrame {
  double x0 = 0, y0 = 0, dx = 1, dy = 1;
  // A window of a larger raster (marks block by block): x0, y0 are the
  // raster's first cell centre and the window starts at its cell (col0,
  // row0). A cell coordinate is the raster's minus a whole number, which is
  // exact, so a window sees the object where the whole raster does.
  int col0 = 0, row0 = 0;
  static GridFrame of(const terrain::GeoReference& geo);
  Eigen::Vector3d to_cell(const Eigen::Vector3d& world) const {
    return {(world.x() - x0) / dx - col0, (y0 - world.y()) / dy - row0, world.z()};
  }
  Eigen::Vector3d to_world(double col, double row, double z) const {
    return {x0 + (col + col0) * dx, y0 - (row + row0) * dy, z};
  }
};

// A mesh with its vertex normals (area-weighted, outward for counter-clockwise
// triangles) and its bounding radius about its origin.
struct ObjectShape {
  terrain::Mesh mesh;
  std::vector<Eigen::Vector3d> normals;
  double radius = 0.0;  // m
  static ObjectShape of(terrain::Mesh mesh);
};

// The object's triangles at `pose`, in cell space.
CellTriangles posed_triangles(const ObjectShape& shape, const Pose& pose, const GridFrame& frame);

// The object swept by translation from `from` to `to.position`, both with
// to.rotation (paper 000, 3.3): with d the motion and n the outward vertex
// normals, a triangle whose n.d are all positive stands at the current
// position; one whose signs are mixed, all zero, or positive and zero is
// extruded into a prism between the two positions; the rest stand at the
// previous position. Rotation is left to sub-steps, as in the paper.
CellTriangles swept_triangles(const ObjectShape& shape, const Eigen::Vector3d& from, const Pose& to,
                              const GridFrame& frame);

}  // namespace drift::marks
