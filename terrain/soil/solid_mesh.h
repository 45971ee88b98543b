// A closed triangle mesh as a solid body for the soil (issue 33, item 5: a
// bucket or blade from a modeller). The mesh, in the body's frame, is
// voxelised once on a grid of its own (finer than the soil's voxels) by ray
// parity along z: a cell is inside where a vertical line through its centre
// has crossed the surface an odd number of times below it. The body is then
// placed at its pose every step by looking points up in that grid (the same
// sampled coverage as a rotated primitive, primitives.h).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "terrain/mesh.h"

namespace drift::soil {

class SolidMesh {
 public:
  // Largest number of cells the mesh's own grid may have.
  static constexpr std::uint64_t kMaxCells = 1ull << 27;

  // `mesh` in metres in the body's frame; `cell` metres. Throws drift::Error
  // naming `name` for an empty mesh, non-finite vertices, a cell that would
  // need more than kMaxCells, or a mesh that encloses nothing (not closed).
  SolidMesh(const terrain::Mesh& mesh, double cell, const std::string& name);

  bool inside(const Eigen::Vector3d& p) const;  // p in the body's frame
  // The body-frame box [lo, hi] against the solid cells: 1 if every cell it
  // overlaps is solid, 0 if none is, -1 if some are.
  int classify(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) const;
  const Eigen::Vector3d& lower() const { return lo_; }
  const Eigen::Vector3d& upper() const { return hi_; }
  std::uint64_t solid_cells() const { return solid_cells_; }

 private:
  Eigen::Vector3d lo_, hi_;
  double cell_ = 0;
  int n_[3] = {0, 0, 0};
  std::vector<std::uint8_t> solid_;  // x fastest, then y, then z
  std::uint64_t solid_cells_ = 0;
};

}  // namespace drift::soil
