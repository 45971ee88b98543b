// The [[objects]] list shared by scene files (drift render) and object files
// (drift snow fall --objects): each entry places an OBJ mesh with keys
// mesh (path, relative to the file), position [x, y, z] (CRS metres), scale,
// rotate_z (degrees, counter-clockwise seen from above), y_up (OBJ is y-up) and
// color (albedo, used by the renderer only).
#pragma once

#include <toml++/toml.h>

#include <filesystem>
#include <vector>

#include "render/render_settings.h"
#include "terrain/grid.h"

namespace drift::pipeline {

// Reads root's [[objects]] (none: empty). Meshes are loaded, scaled and rotated;
// errors name the file, the line and the key.
std::vector<terrain::PlacedMesh> read_objects(const toml::table& root,
                                              const std::filesystem::path& file);

// A TOML file holding only [[objects]] entries.
std::vector<terrain::PlacedMesh> read_objects_file(const std::filesystem::path& path);

// Throws drift::Error if `raster` (read from `path`) is in a geographic CRS
// (degrees), telling the user to run drift import first.
void require_metric_crs(const terrain::HeightField& raster, const std::filesystem::path& path);

}  // namespace drift::pipeline
