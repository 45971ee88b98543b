// The ground truth of one frame as JSON (docs/rendering.md, "Ground truth
// sidecar"), so that a dataset loader needs nothing else: the image size,
// the camera's intrinsics (OpenCV's pinhole K, or a map's geotransform) and
// pose in the DEM's CRS, the sun's direction, the CRS and the EXR's P
// origin, and the class and object names with their Cryptomatte IDs.
#pragma once

#include <string>

#include "render/camera.h"
#include "render/render_settings.h"

namespace drift::render {

class TerrainScene;

// The sidecar of a frame rendered by render_image with these arguments.
std::string frame_sidecar_json(const TerrainScene& scene, const SceneInput& input,
                               const Camera& camera, const RenderSettings& settings);

}  // namespace drift::render
