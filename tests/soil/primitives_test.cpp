// Voxelising primitives with partial coverage (paper 004, sec. 3.2.4).
#include "terrain/soil/primitives.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "terrain/error.h"

namespace drift::soil {
namespace {

double volume(const Primitive& p, double voxel) {
  terrain::Grid3Shape g{40, 40, 40, voxel, {-2, -2, -2}};
  std::vector<float> field(g.count(), 0.0f);
  add_coverage({p}, Eigen::Vector3d::Zero(), g, field);
  return std::accumulate(field.begin(), field.end(), 0.0) * voxel * voxel * voxel;
}

// Volumes against closed forms, within 2 % on 0.1 m voxels.
TEST(SoilPrimitives, VolumesMatchClosedForms) {
  const double r = 0.9;
  EXPECT_NEAR(volume({PrimitiveKind::Sphere, {0, 0, 0}, {r, 0, 0}}, 0.1),
              4.0 / 3 * M_PI * r * r * r, 0.02 * 3.05);
  EXPECT_NEAR(volume({PrimitiveKind::Ellipsoid, {0, 0, 0}, {0.9, 0.5, 0.7}}, 0.1),
              4.0 / 3 * M_PI * 0.9 * 0.5 * 0.7, 0.02 * 1.32);
  EXPECT_NEAR(volume({PrimitiveKind::Cylinder, {0, 0, 0}, {0.6, 0, 0.8}}, 0.1), M_PI * 0.36 * 1.6,
              0.02 * 1.81);
  EXPECT_NEAR(volume({PrimitiveKind::Cone, {0, 0, -1}, {0.8, 0, 1.5}}, 0.1), M_PI * 0.64 * 1.5 / 3,
              0.02 * 1.0);
  // A cuboid off the lattice is exact (analytic overlap).
  EXPECT_NEAR(volume({PrimitiveKind::Cuboid, {0.033, 0.071, 0.019}, {0.523, 0.311, 0.257}}, 0.1),
              8 * 0.523 * 0.311 * 0.257, 1e-5);
}

TEST(SoilPrimitives, CoverageIsPartialAtTheBoundary) {
  const Primitive slab{PrimitiveKind::Cuboid, {0, 0, 0.25}, {5, 5, 0.25}};  // top at z = 0.5
  EXPECT_DOUBLE_EQ(coverage({slab}, Eigen::Vector3d::Zero(), {0, 0, 0}, {1, 1, 1}), 0.5);
  EXPECT_DOUBLE_EQ(coverage({slab}, Eigen::Vector3d(0, 0, -1), {0, 0, 0}, {1, 1, 1}), 0.0);
}

TEST(SoilPrimitives, BadSizesAreRefused) {
  RigidObject o{"blade", {{PrimitiveKind::Cuboid, {0, 0, 0}, {1, -1, 1}}}, {}};
  EXPECT_THROW(validate(o, "body"), Error);
  o.primitives[0].size = {1, NAN, 1};
  EXPECT_THROW(validate(o, "body"), Error);
  o.primitives[0].size = {1, 1, 1};
  o.path = {{1.0, {0, 0, 0}}, {0.5, {1, 0, 0}}};
  EXPECT_THROW(validate(o, "body"), Error);
  o.path = {{0.0, {0, 0, 0}}, {2.0, {1, 0, 0}}};
  EXPECT_NO_THROW(validate(o, "body"));
  EXPECT_NEAR(o.velocity(1.0).x(), 0.5, 1e-12);
  EXPECT_NEAR(o.position(1.0).x(), 0.5, 1e-12);
}

}  // namespace
}  // namespace drift::soil
