#include "render/frame_sidecar.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "render/camera_setup.h"
#include "render/cryptomatte.h"
#include "render/mattes.h"
#include "render/terrain_scene.h"
#include "terrain/angles.h"
#include "terrain/direction.h"
#include "terrain/json_text.h"

namespace drift::render {

namespace {

std::string number(double v) { return terrain::json_number(v); }

std::string vec(const Eigen::Vector3d& v) {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "[" + string.
  std::string text = "[";
  text.append(number(v.x())).append(", ").append(number(v.y())).append(", ");
  return text.append(number(v.z())).append("]");
}

// Names with their Cryptomatte IDs: {"name": {"id_hex": ..., "id": float}}.
std::string ids(const CryptomatteLayer& layer) {
  std::string out = "{";
  for (std::size_t i = 0; i < layer.names.size(); ++i) {
    const float id = cryptomatte_id(layer.names[i]);
    out += (i ? ", " : "") + terrain::json_string(layer.names[i]) +
           ": {\"id_hex\": " + terrain::json_string(cryptomatte_hex(id)) +
           ", \"id\": " + number(id) + "}";
  }
  return out + "}";
}

}  // namespace

std::string frame_sidecar_json(const TerrainScene& scene, const SceneInput& input,
                               const Camera& camera, const RenderSettings& settings) {
  const CameraRays rays = make_camera_rays(scene, camera, settings.width, settings.height);
  const int w = settings.width, h = settings.height;
  const Eigen::Vector3d world_origin = scene.origin().array().round().matrix();
  // OpenCV's camera axes: x right, y down, z forward; their columns in the
  // CRS (east, north, up) are the camera-to-world rotation.
  const Eigen::Vector3d x = rays.right.cast<double>(), y = -rays.up.cast<double>(),
                        z = rays.forward.cast<double>();
  const Eigen::Vector3d eye = scene.origin() + rays.eye.cast<double>();
  std::ostringstream j;
  j << "{\n  \"format\": \"drift frame sidecar 1\",\n";
  j << "  \"image\": {\"width\": " << w << ", \"height\": " << h << "},\n";
  if (rays.orthographic()) {
    const double cell = 2.0 * rays.half_height / h;
    const auto& b = camera.map_box;
    j << "  \"projection\": \"map\",\n";
    j << "  \"intrinsics\": {\"metres_per_pixel\": " << number(cell) << ", \"geotransform\": ["
      << number(b[0]) << ", " << number(cell) << ", 0, " << number(b[3]) << ", 0, " << number(-cell)
      << "]},\n";
  } else {
    // Square pixels: the same focal length in pixels both ways; OpenCV puts
    // pixel centres on integers, so the image's centre is (w/2 - 1/2, ...).
    const double f = 0.5 * h / rays.tan_half;
    j << "  \"projection\": \"perspective\",\n";
    j << "  \"intrinsics\": {\"fx\": " << number(f) << ", \"fy\": " << number(f)
      << ", \"cx\": " << number(0.5 * w - 0.5) << ", \"cy\": " << number(0.5 * h - 0.5)
      << ", \"K\": [[" << number(f) << ", 0, " << number(0.5 * w - 0.5) << "], [0, " << number(f)
      << ", " << number(0.5 * h - 0.5) << "], [0, 0, 1]]"
      << ", \"vertical_fov_deg\": " << number(terrain::degrees(2.0 * std::atan(rays.tan_half)))
      << ", \"lens_radius_m\": " << number(rays.lens_radius)
      << ", \"focus_distance_m\": " << number(rays.focus_distance) << "},\n";
  }
  // world_to_camera maps CRS points to OpenCV camera coordinates:
  // p_cam = R^T (p - position), rows of R^T being x, y, z.
  j << "  \"camera\": {\"position\": " << vec(eye) << ",\n    \"axes\": \"OpenCV: x right, y down, "
    << "z forward; rotation columns are those axes in the CRS (x east, y north, z up)\",\n"
    << "    \"rotation\": [[" << number(x.x()) << ", " << number(y.x()) << ", " << number(z.x())
    << "], [" << number(x.y()) << ", " << number(y.y()) << ", " << number(z.y()) << "], ["
    << number(x.z()) << ", " << number(y.z()) << ", " << number(z.z()) << "]],\n"
    << "    \"world_to_camera\": [[" << number(x.x()) << ", " << number(x.y()) << ", "
    << number(x.z()) << ", " << number(-x.dot(eye)) << "], [" << number(y.x()) << ", "
    << number(y.y()) << ", " << number(y.z()) << ", " << number(-y.dot(eye)) << "], ["
    << number(z.x()) << ", " << number(z.y()) << ", " << number(z.z()) << ", "
    << number(-z.dot(eye)) << "], [0, 0, 0, 1]]},\n";
  const Eigen::Vector3d sun =
      terrain::direction_from_az_el(input.sun.azimuth_deg, input.sun.elevation_deg);
  j << "  \"sun\": {\"azimuth_deg\": " << number(input.sun.azimuth_deg)
    << ", \"elevation_deg\": " << number(input.sun.elevation_deg) << ", \"direction\": " << vec(sun)
    << "},\n";
  j << "  \"crs_wkt\": " << terrain::json_string(input.terrain.geo().crs_wkt) << ",\n";
  j << "  \"origin\": " << vec(world_origin)
    << ",\n  \"origin_note\": \"the EXR's P.X/Y/Z plus origin is the point in the CRS\",\n";
  const FrameMattes mattes(scene, input);
  j << "  \"cryptomatte\": {\"hash\": \"MurmurHash3_32\", \"conversion\": \"uint32_to_float32\", "
       "\"empty_id\": 0},\n";
  j << "  \"classes\": " << ids(mattes.material()) << ",\n";
  j << "  \"objects\": " << ids(mattes.object()) << "\n}\n";
  return j.str();
}

}  // namespace drift::render
