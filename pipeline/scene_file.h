// Scene files (TOML) for `drift render`: parsing with strict validation.
// Unknown keys, wrong types and out-of-range values are drift::Error naming the
// key, the file and the line. See docs/rendering.md for every key.
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/scene.h"
#include "pipeline/scene_variables.h"
#include "render/render_settings.h"
#include "render/solar_position.h"
#include "render/tonemap.h"

namespace drift::pipeline {

// The scene file's sections, the stages' (pipeline/scene_products.h) among
// the renderer's own, in the order they are read and listed in errors.
std::vector<std::string> scene_sections();

// Parses and validates; meshes are loaded, the terrain raster is not.
// `variables` replace the defaults of the file's [variables] table
// (pipeline/scene_variables.h).
SceneFile read_scene_file(const std::filesystem::path& path, const SceneVariables& variables = {});

// Every file the scene reads (rasters, masks, product files, the objects file
// and every mesh its objects name), for refusing
// them as outputs.
std::vector<std::filesystem::path> scene_inputs(const SceneFile& scene);

// Replaces the scene's camera path with the [[camera.keyframe]] entries of
// the TOML file `path` (drift render --camera-path): one path for many
// scenes, or many paths for one.
void read_camera_path(const std::filesystem::path& path, SceneFile& scene);

// Reads the scene's terrain raster and layer rasters; a geographic (degree)
// raster is an error telling the user to run `drift import` first.
void load_scene_terrain(SceneFile& scene);

}  // namespace drift::pipeline
