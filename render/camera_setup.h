// A camera placed in a scene: the view used when a scene names none, and the
// primary rays of a camera in the scene's local frame (render/camera.h holds
// the camera and its rays; this component needs the scene to place them).
#pragma once

#include "render/camera.h"

namespace drift::render {

class TerrainScene;

// The camera used when a scene names none: from above the DEM's southern edge,
// looking north at its highest point.
Camera default_camera(const TerrainScene& scene);

// The rays of `camera` over a width x height image in `scene`'s local frame
// (a map's: straight down over its box).
CameraRays make_camera_rays(const TerrainScene& scene, const Camera& camera, int width, int height);

}  // namespace drift::render
