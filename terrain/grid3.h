// A 3-D grid of values on cubic voxels: the plain data type for volumes
// (voxel soil's density, velocity and collision fields; anything that needs a
// density sampled on a lattice).
//
// Layout: z (up) runs fastest, then x (east), then y (north), so that a column
// of voxels is contiguous: the column walks (height spans, top surfaces,
// overflow carried upwards) read memory in order, and x/y neighbours are a
// fixed stride away for stencils. Voxel (x, y, z) covers
// origin + voxel_size * [x, x+1) x [y, y+1) x [z, z+1) in metres.
#pragma once

#include <Eigen/Core>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "terrain/error.h"

namespace drift::terrain {

struct Grid3Shape {
  int nx = 0, ny = 0, nz = 0;
  double voxel_size = 1.0;                // metres, the edge of a cubic voxel
  Eigen::Vector3d origin{0.0, 0.0, 0.0};  // metres, the corner of voxel (0, 0, 0)

  std::size_t count() const {
    return static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) *
           static_cast<std::size_t>(nz);
  }
  std::size_t columns() const { return static_cast<std::size_t>(nx) * ny; }
  // Index of voxel (x, y, z); z fastest.
  std::size_t index(int x, int y, int z) const {
    assert(x >= 0 && x < nx && y >= 0 && y < ny && z >= 0 && z < nz);
    return (static_cast<std::size_t>(y) * nx + x) * nz + z;
  }
  // Index of the bottom voxel of column (x, y).
  std::size_t column(int x, int y) const { return (static_cast<std::size_t>(y) * nx + x) * nz; }
  bool contains(int x, int y, int z) const {
    return x >= 0 && x < nx && y >= 0 && y < ny && z >= 0 && z < nz;
  }
  // Centre of voxel (x, y, z) in metres.
  Eigen::Vector3d center(int x, int y, int z) const {
    return origin + voxel_size * Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5);
  }
  // Strides between neighbours along each axis.
  std::ptrdiff_t stride_x() const { return nz; }
  std::ptrdiff_t stride_y() const { return static_cast<std::ptrdiff_t>(nx) * nz; }
};

template <class T>
class Grid3 {
 public:
  Grid3() = default;
  explicit Grid3(const Grid3Shape& shape, T fill = T{})
      : shape_(shape), data_(shape.count(), fill) {
    if (shape.nx <= 0 || shape.ny <= 0 || shape.nz <= 0)
      throw Error("a 3-D grid needs positive sizes, got " + std::to_string(shape.nx) + " x " +
                  std::to_string(shape.ny) + " x " + std::to_string(shape.nz));
  }

  const Grid3Shape& shape() const { return shape_; }
  int nx() const { return shape_.nx; }
  int ny() const { return shape_.ny; }
  int nz() const { return shape_.nz; }
  std::size_t size() const { return data_.size(); }

  T& operator()(int x, int y, int z) { return data_[shape_.index(x, y, z)]; }
  const T& operator()(int x, int y, int z) const { return data_[shape_.index(x, y, z)]; }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  std::vector<T>& values() { return data_; }
  const std::vector<T>& values() const { return data_; }

 private:
  Grid3Shape shape_;
  std::vector<T> data_;
};

}  // namespace drift::terrain
