// Rigid bodies and soil bodies as unions of geometric primitives (paper 004,
// sec. 3.2.4 and fig. 37, after Laprairie's volume sampling functions), and
// their voxelisation with partial coverage at the boundary.
//
// Primitives are axis-aligned in their body's frame (cylinders and cones
// stand along its z). A body moves along keyframes, linearly between them,
// and turns about its position: keyframed orientations (slerp between them)
// and a constant spin (a rotating blade, a tilting bucket; issue 33, item 5).
// A body may also be a closed triangle mesh (solid_mesh.h), voxelised in its
// own frame once and placed at its pose every step.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <memory>
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
  // True if no point within r of p is inside (conservative for the ellipsoid).
  bool misses_ball(const Eigen::Vector3d& p, double r) const;
  // True if every point within r of p is inside (sphere, cuboid, cylinder;
  // false, undecided, for the ellipsoid and the cone).
  bool holds_ball(const Eigen::Vector3d& p, double r) const;
  Eigen::Vector3d lower() const;  // bounding box
  Eigen::Vector3d upper() const;
};

struct Keyframe {
  double time = 0.0;  // seconds
  Eigen::Vector3d position{0, 0, 0};
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // body to world
};

// A body's placement at one time: its frame's origin (the pivot it turns
// about) and its rotation, body to world.
struct Pose {
  Eigen::Vector3d position{0, 0, 0};
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  bool rotated() const { return rotation != Eigen::Matrix3d::Identity(); }
  Eigen::Vector3d to_body(const Eigen::Vector3d& w) const {
    return rotation.transpose() * (w - position);
  }
};

class SolidMesh;  // terrain/soil/solid_mesh.h

struct RigidObject {
  std::string name;
  std::vector<Primitive> primitives;
  std::vector<Keyframe> path;  // sorted by time; one keyframe (or none) = static
  // Constant angular velocity (rad/s, world axes) about the body's position,
  // on top of the keyframes' orientation.
  Eigen::Vector3d spin{0, 0, 0};
  // A closed triangle mesh in the body's frame, part of the solid with the
  // primitives (either may be empty, not both).
  std::shared_ptr<const SolidMesh> mesh;

  bool moves() const;
  Eigen::Vector3d position(double t) const;  // held at the ends
  Eigen::Vector3d velocity(double t) const;  // m/s, of the segment holding t
  Eigen::Quaterniond orientation(double t) const;
  Eigen::Vector3d angular_velocity(double t) const;  // rad/s, world axes
  Pose pose(double t) const;
};

// Throws drift::Error naming `what`, the primitive and the value for a
// non-finite or non-positive size, non-finite centre, keyframe or spin, or
// keyframes out of time order.
void validate(const RigidObject& object, const std::string& what);

// A solid at a pose: the union of `primitives` and `mesh` (may be null),
// both in the body's frame.
struct PlacedSolid {
  const std::vector<Primitive>* primitives = nullptr;
  const SolidMesh* mesh = nullptr;
  Pose pose;
};
PlacedSolid placed(const RigidObject& body, double t);

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
VoxelBox voxel_box(const PlacedSolid& solid, const terrain::Grid3Shape& shape);
// Fraction of the world box [lo, hi] inside a placed solid: as above when it
// is not rotated and has no mesh, else refined_share(..., kRefineDepth).
double coverage(const PlacedSolid& solid, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

// The share of the world box [lo, hi] inside a turned (or mesh) solid,
// converging to the exact one (issue 33's follow-up; before, 4 x 4 x 4
// samples): a box is wholly inside if one convex primitive holds its eight
// corners (turned into the body's frame), wholly outside if its bounding ball
// misses every primitive (Primitive::misses_ball) and it overlaps none of the
// mesh's solid cells (the mesh's solid, SolidMesh::classify), and exact where only one cuboid
// meets it (the box clipped by the cuboid's planes, its volume by the
// divergence theorem); otherwise it is split in eight, `depth` times, and a
// box still undecided at the end takes the share of its 2 x 2 x 2 sub-box
// centres. The error is at most the undecided boxes' volume, added to
// `*undecided` as a fraction of [lo, hi] when given: it halves with each
// level (the boxes a surface crosses), and is 0 for a lone turned cuboid.
inline constexpr int kRefineDepth = 3;
double refined_share(const PlacedSolid& solid, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                     int depth, double* undecided = nullptr);

// Calls fill(i, c) for each voxel i (an index of `shape`) in the voxel box of
// `primitives` at `position` that they cover by a fraction c > 0. Parallel
// over rows y: `fill` may touch voxel i only.
void for_each_covered_voxel(const std::vector<Primitive>& primitives,
                            const Eigen::Vector3d& position, const terrain::Grid3Shape& shape,
                            const std::function<void(std::size_t, float)>& fill);
void for_each_covered_voxel(const PlacedSolid& solid, const terrain::Grid3Shape& shape,
                            const std::function<void(std::size_t, float)>& fill);

// Adds the coverage of the object at `position` to `field` (saturating at
// 1) over its voxel box. Parallel over rows; the same bits on any thread count.
void add_coverage(const std::vector<Primitive>& primitives, const Eigen::Vector3d& position,
                  const terrain::Grid3Shape& shape, std::vector<float>& field);
void add_coverage(const PlacedSolid& solid, const terrain::Grid3Shape& shape,
                  std::vector<float>& field);

}  // namespace drift::soil
