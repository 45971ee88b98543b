// Which object a camera ray sees first, for the object mattes
// (render/cryptomatte.h): the scene's objects in an Embree scene of their
// own (the terrain left out), in the TerrainScene's local frame. A ray's
// first hit is an object's when this scene meets that object no farther
// than the whole scene's hit. Costs one ray per camera sample through the
// objects' BVH, and nothing without objects.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "terrain/mesh.h"

namespace drift::render {

class ObjectLocator {
 public:
  // `origin`: the CRS point of the local frame (TerrainScene::origin()).
  ObjectLocator(const std::vector<terrain::PlacedMesh>& meshes, const Eigen::Vector3d& origin);
  ~ObjectLocator();
  ObjectLocator(const ObjectLocator&) = delete;
  ObjectLocator& operator=(const ObjectLocator&) = delete;

  // The index of the object the ray (local frame) meets at `distance`, the
  // whole scene's first hit, or -1 when that hit is not on an object.
  int object_at(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float distance) const;

 private:
  struct Embree;
  std::unique_ptr<Embree> embree_;
};

}  // namespace drift::render
