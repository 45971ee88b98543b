// Reading OBJ meshes (tinyobjloader), writing OBJ, and writing PLY meshes (with per-vertex
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
// The origin is written as a comment "origin X Y Z" (CRS metres).
void write_ply(const Mesh& mesh, const std::filesystem::path& path);

// Wavefront OBJ: v x y z [vn], triangles as f a//a b//b c//c (1-based),
// the origin as a comment "# origin X Y Z". z-up as stored, or y-up (the
// OBJ convention, (x, y, z) -> (x, z, -y)) when `y_up`. Written atomically.
void write_obj(const Mesh& mesh, const std::filesystem::path& path, bool y_up = false);

// Reads the PLY files write_ply writes (binary little-endian, float vertex
// properties, triangle faces as "list uchar int"): positions, normals if
// there, every other vertex property as a named attribute, and the origin
// comment. Anything else is a drift::Error naming the file and what differs.
Mesh read_ply(const std::filesystem::path& path);

// Splits a mesh by a per-vertex integer attribute (e.g. "object"): part k holds
// the vertices whose value is k and the triangles among them, attributes and
// origin carried along. Throws drift::Error if the attribute is missing.
std::vector<Mesh> split_by_attribute(const Mesh& mesh, const std::string& name);

}  // namespace drift::terrain
