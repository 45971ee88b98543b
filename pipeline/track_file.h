// Track files for drift marks: the [[objects]] entries of scenes and object
// files (pipeline/object_list.h: mesh, position, scale, rotate_z, y_up) with
// keyframes, and a few top-level keys:
//
//   step = 0.1                 # s per simulation step (required), (0, 3600]
//   material = "sand"          # the ground's material: a preset (sand, mud,
//                              # snow) or a table {preset, theta, alpha, roughness}
//   [camera]                   # optional, for resolution = "auto" (paper 000, 3.6)
//   position = [x, y, z]       # CRS metres
//   fov = 40                   # horizontal, degrees
//   width = 1280               # pixels
//   [[objects]]
//   mesh = "shoe.obj"          # + position (added to every keyframe), scale, ...
//   material = "mud"           # optional: the ground's material where it walks
//   motion = "sweep"           # sweep | substeps | place (paper 000, table 1)
//   resolution = 1             # 1, 2, 4 (full, half, quarter) or "auto"
//   follow_ground = false      # keyframe z = height above the ground
//   [[objects.keyframes]]
//   time = 0.0                 # s, increasing
//   position = [x, y, z]       # the mesh origin, CRS metres (z absolute)
//   rotation = [yaw, pitch, roll]   # degrees (or quaternion = [w, x, y, z])
#pragma once

#include <toml++/toml.h>

#include <filesystem>
#include <optional>
#include <vector>

#include "terrain/marks/marks.h"

namespace drift::pipeline {

struct TrackFile {
  double step = 0.1;
  std::optional<marks::Material> material;
  std::optional<marks::MarksCamera> camera;
  std::vector<marks::MarkObject> objects;
};

// Throws drift::Error naming the file, the line and the key for anything
// malformed: a missing or unreadable mesh, NaN, keyframes out of order, unknown
// keys or materials.
TrackFile read_track_file(const std::filesystem::path& path);

// A material from a track file's value: a preset's name or a table of
// preset (optional), theta (deg), alpha, roughness (sigma).
marks::Material read_material_value(const toml::node& node, const std::filesystem::path& file,
                                    const std::string& key);

}  // namespace drift::pipeline
