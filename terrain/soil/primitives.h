// Rigid bodies and soil bodies as unions of geometric primitives (paper 004,
// sec. 3.2.4 and fig. 37, after Laprairie's volume sampling functions), and
// their voxelisation with partial coverage at the boundary.
//
// Primitives are axis-aligned (cylinders and cones stand along z); an object
// moves by translation along keyframes, linearly between them.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "terrain/grid3.h"

namespace drift::soil {

enum class PrimitiveKind { Sphere, Ellipsoid, Cuboid, Cylinder, Cone };

// Sizes in metres; `center` relative to the object's position.
//   sphere:    size.x() = radius
//   ellipsoid: size = semi-axes
//   cuboid:    size = half extents
//   cylinder:  size.x() = radius, size.z() = half height (axis along z)
//   cone:      size.x() = base radius, size.z() = height; center = base centre, apex up
struct Primitive {
  PrimitiveKind kind = PrimitiveKind::Cuboid;
  Eigen::Vector3d center{0, 0, 0};
  Eigen::Vector3d size{1, 1, 1};

  bool inside(const Eigen::Vector3d& p) const;  // p relative to the object's position
  Eigen::Vector3d lower() const;                // bounding box
  Eigen::Vector3d upper() const;
};

struct Keyframe {
  double time = 0.0;  // seconds
  Eigen::Vector3d position{0, 0, 0};
};

struct RigidObject {
  std::string name;
  std::vector<Primitive> primitives;
  std::vector<Keyframe> path;  // sorted by time; one keyframe (or none) = static

  bool moves() const { return path.size() > 1; }
  Eigen::Vector3d position(double t) const;  // held at the ends
  Eigen::Vector3d velocity(double t) const;  // m/s, of the segment holding t
};

// Throws drift::Error naming `what`, the primitive and the value for a
// non-finite or non-positive size, non-finite centre or keyframe, or
// keyframes out of time order.
void validate(const RigidObject& object, const std::string& what);

// Fraction of the box [lo, hi] (metres, world) inside the union of
// `primitives` placed at `position`: 1 if one primitive holds all corners
// (they are convex), exact for a lone cuboid, else 4 x 4 x 4 samples.
double coverage(const std::vector<Primitive>& primitives, const Eigen::Vector3d& position,
                const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

// Voxel index box [lo, hi) touched by `primitives` at `position`, clipped
// to the grid (empty when lo >= hi on any axis).
struct VoxelBox {
  Eigen::Vector3i lo{0, 0, 0}, hi{0, 0, 0};
  bool empty() const { return (hi.array() <= lo.array()).any(); }
};
VoxelBox voxel_box(const std::vector<Primitive>& primitives, const Eigen::Vector3d& position,
                   const terrain::Grid3Shape& shape);

// Calls fill(i, c) for each voxel i (an index of `shape`) in the voxel box of
// `primitives` at `position` that they cover by a fraction c > 0. Parallel
// over rows y: `fill` may touch voxel i only.
void for_each_covered_voxel(const std::vector<Primitive>& primitives,
                            const Eigen::Vector3d& position, const terrain::Grid3Shape& shape,
                            const std::function<void(std::size_t, float)>& fill);

// Adds the coverage of the object at `position` to `field` (saturating at
// 1) over its voxel box. Parallel over rows; the same bits on any thread count.
void add_coverage(const std::vector<Primitive>& primitives, const Eigen::Vector3d& position,
                  const terrain::Grid3Shape& shape, std::vector<float>& field);

}  // namespace drift::soil
