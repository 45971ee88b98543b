// Reading OBJ meshes (tinyobjloader) and writing PLY meshes (with per-vertex
// attributes as extra properties, which Blender, MeshLab and CloudCompare read).
#pragma once

#include <filesystem>

#include "terrain/mesh.h"

namespace drift::terrain {

// Triangulates polygons. Throws drift::Error naming the file for a missing or
// malformed file, indices out of range, non-finite coordinates or an empty mesh.
// OBJ files are y-up by convention; `y_up = true` turns them into our z-up frame
// (x, y, z) -> (x, -z, y).
Mesh read_obj(const std::filesystem::path& path, bool y_up = false);

// Binary little-endian PLY: x y z [nx ny nz] [attributes...] and triangle faces.
// Written atomically.
void write_ply(const Mesh& mesh, const std::filesystem::path& path);

}  // namespace drift::terrain
