#include "render/object_ids.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>

#include "render/embree_ray.h"
#include "terrain/error.h"

namespace drift::render {

struct ObjectLocator::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

ObjectLocator::ObjectLocator(const std::vector<terrain::PlacedMesh>& meshes,
                             const Eigen::Vector3d& origin) {
  if (meshes.empty()) return;
  embree_ = std::make_unique<Embree>();
  embree_->device = rtcNewDevice("threads=0");
  if (!embree_->device) throw Error("cannot create an Embree device");
  embree_->scene = rtcNewScene(embree_->device);
  // Geometry id = object index: the same shift to local coordinates as the
  // TerrainScene's (CRS position minus its origin, in double), so the two
  // scenes' triangles are the same floats.
  for (const terrain::PlacedMesh& placed : meshes) {
    RTCGeometry geom = rtcNewGeometry(embree_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                          RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                          placed.mesh.positions.size()));
    const Eigen::Vector3d shift = placed.position - origin;
    for (std::size_t i = 0; i < placed.mesh.positions.size(); ++i) {
      const Eigen::Vector3d local = placed.mesh.positions[i].cast<double>() + shift;
      for (int c = 0; c < 3; ++c) v[3 * i + c] = static_cast<float>(local[c]);
    }
    auto* idx = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), placed.mesh.triangles.size()));
    for (std::size_t t = 0; t < placed.mesh.triangles.size(); ++t)
      for (int c = 0; c < 3; ++c)
        idx[3 * t + c] = static_cast<unsigned>(placed.mesh.triangles[t][c]);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(embree_->scene, geom);
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(embree_->scene);
}

ObjectLocator::~ObjectLocator() = default;

int ObjectLocator::object_at(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                             float distance) const {
  if (!embree_) return -1;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh = nearest_ray_hit(o, d);
  rtcIntersect1(embree_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return -1;
  // The same triangles traced the same way meet at the same distance; the
  // tolerance covers the whole scene's other BVH's rounding.
  const float tolerance = 1e-4f * (1.0f + std::max(distance, 0.0f));
  return rh.ray.tfar <= distance + tolerance ? static_cast<int>(rh.hit.geomID) : -1;
}

}  // namespace drift::render
