#include "render/camera_setup.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "render/terrain_scene.h"
#include "terrain/error.h"

namespace drift::render {

namespace {

using Eigen::Vector3f;

// A map's eye stands this far above the highest geometry: rays start in the
// air above everything, and the air they cross to the ground is the little
// that lies between (aerial perspective stays a map's, not a view's).
constexpr float kMapClearance = 10.0f;

CameraRays map_rays(const TerrainScene& scene, const Camera& camera, int width, int height) {
  const auto& b = camera.map_box;
  if (!(b[2] > b[0]) || !(b[3] > b[1]))
    throw Error("the map's box must have east > west and north > south");
  CameraRays p;
  const Vector3f centre =
      scene.to_local(Eigen::Vector3d(0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3]), 0.0));
  p.eye = {centre.x(), centre.y(), scene.top() + kMapClearance};
  p.forward = -Vector3f::UnitZ();
  p.right = Vector3f::UnitX();
  p.up = Vector3f::UnitY();
  p.half_width = static_cast<float>(0.5 * (b[2] - b[0]));
  p.half_height = static_cast<float>(0.5 * (b[3] - b[1]));
  p.aspect = static_cast<float>(width) / static_cast<float>(height);
  p.width = width;
  p.height = height;
  return p;
}

}  // namespace

Camera default_camera(const TerrainScene& scene) {
  // Stand on the far side of the DEM's centre from its highest point, above the
  // terrain, and look at the summit across the whole DEM. A summit at the very
  // centre is looked at from the south.
  const Vector3f top = scene.highest_point();
  Eigen::Vector2f away = -top.head<2>();
  if (away.norm() < 1e-3f * scene.extent().norm()) away = {0.0f, -1.0f};
  away.normalize();
  const float half = 0.5f * scene.extent().minCoeff();
  const Eigen::Vector2f xy = away * (0.9f * half);
  // Slightly above the summit, so ridges between camera and peak do not hide it.
  const float z = std::max(scene.height_at(xy.x(), xy.y()), top.z()) + 0.12f * half;
  const Eigen::Vector3d origin = scene.origin();
  Camera camera;
  camera.from = origin + Eigen::Vector3d(xy.x(), xy.y(), z);
  // Aim a little below the summit: the peak sits in the upper part of the frame
  // and the slopes in front fill the rest.
  camera.to = origin + top.cast<double>() - Eigen::Vector3d(0, 0, 0.25 * half);
  camera.vertical_fov_deg = 45.0;
  return camera;
}

CameraRays make_camera_rays(const TerrainScene& scene, const Camera& camera, int width,
                            int height) {
  if (camera.projection == Projection::Map) return map_rays(scene, camera, width, height);
  CameraRays p;
  p.eye = scene.to_local(camera.from);
  p.forward = scene.to_local(camera.to) - p.eye;
  if (!(p.forward.norm() > 0.0f)) throw Error("camera 'from' and 'to' are the same point");
  p.forward.normalize();
  p.right = p.forward.cross(Vector3f::UnitZ());
  if (p.right.norm() < 1e-6f) p.right = p.forward.cross(Vector3f::UnitY());
  p.right.normalize();
  p.up = p.right.cross(p.forward);
  p.aspect = static_cast<float>(width) / static_cast<float>(height);
  if (camera.focal_length_mm) {
    // Horizontal half-width of the sensor over the focal length.
    p.tan_half =
        static_cast<float>(camera.sensor_width_mm / (2.0 * *camera.focal_length_mm)) / p.aspect;
    if (camera.f_number > 0.0) {
      p.lens_radius = static_cast<float>(*camera.focal_length_mm / 1000.0 / camera.f_number / 2.0);
      p.focus_distance =
          static_cast<float>(camera.focus_distance.value_or((camera.to - camera.from).norm()));
    }
  } else {
    p.tan_half = static_cast<float>(std::tan(camera.vertical_fov_deg * std::numbers::pi / 360.0));
  }
  p.width = width;
  p.height = height;
  return p;
}

}  // namespace drift::render
