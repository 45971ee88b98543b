// The [[objects]] list shared by scene files (drift render), object files
// (drift snow fall --objects) and track files (drift marks --track): each entry
// places an OBJ or PLY mesh with keys mesh (path, relative to the file),
// position [x, y, z] (CRS metres), scale, rotate_z (degrees, counter-clockwise
// seen from above), y_up (the mesh is y-up) and color (albedo, used by the
// renderer only). Readers that extend the entries (track files' keyframes)
// read their own keys through a callback.
#pragma once

#include <toml++/toml.h>

#include <filesystem>
#include <functional>
#include <vector>

#include "pipeline/toml_section.h"
#include "render/render_settings.h"
#include "terrain/grid.h"

namespace drift::pipeline {

// Reads the keys an extension adds to one [[objects]] entry (its index, from 0).
using ObjectKeys = std::function<void(Section& entry, std::size_t index)>;

// Reads root's [[objects]] (none: empty). Meshes are loaded, scaled and rotated;
// errors name the file, the line and the key. `extra` reads further keys of
// each entry; any key neither reads is an error.
std::vector<terrain::PlacedMesh> read_objects(const toml::table& root,
                                              const std::filesystem::path& file,
                                              const ObjectKeys& extra = {});

// A TOML file holding only [[objects]] entries.
std::vector<terrain::PlacedMesh> read_objects_file(const std::filesystem::path& path);

// The mesh files that the [[objects]] entries of the TOML file `path` (`what`:
// "objects file", "track file") name, resolved as read_objects resolves them; entries
// without a mesh string are skipped (the reader reports them). They are inputs
// of the run, which OutputSet refuses as outputs: `snow fall --mesh-out
// rock.ply` must not replace the rock.ply it reads.
std::vector<std::filesystem::path> object_mesh_paths(const std::filesystem::path& path,
                                                     const char* what);

// The same for an already parsed file's root table.
std::vector<std::filesystem::path> object_mesh_paths(const toml::table& root,
                                                     const std::filesystem::path& path);

// Throws drift::Error if `raster` (read from `path`) is in a geographic CRS
// (degrees), telling the user to run drift import first.
void require_metric_crs(const terrain::HeightField& raster, const std::filesystem::path& path);

}  // namespace drift::pipeline
