// Meshes in and out. Reading: OBJ (tinyobjloader), drift's own PLY, and through
// Assimp glTF/GLB, FBX, STL, DAE and the other formats Assimp reads. Writing: OBJ,
// PLY (per-vertex attributes as extra properties, which Blender, MeshLab and
// CloudCompare read), glTF/GLB (attributes as custom vertex attributes), STL and
// FBX. Units are metres and z is up inside drift; each format's units and up
// axis are converted at the file (docs/meshes.md).
#pragma once

#include <cstdint>
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

// Which way is up in a mesh file. Auto: as the format defines it (glTF and DAE
// y up; FBX from its header's UpAxis; OBJ, PLY, STL and the rest z up as stored,
// since they do not say). Y or Z: the caller (e.g. an objects entry's `y_up`)
// says so, overriding the format.
enum class UpAxis { Auto, Z, Y };

// Any mesh drift reads, chosen by extension: .obj through read_obj, .ply through
// read_ply (both fuzzed and tested longer), anything else Assimp reads through
// Assimp (read_mesh_assimp). Positions come back in metres, z up.
Mesh read_mesh(const std::filesystem::path& path, UpAxis up = UpAxis::Auto);

// Reads one file through Assimp, every file it opens (a .gltf's .bin buffers)
// passing the input checks (regular files only, size known and within memory)
// and read whole into memory before Assimp parses it. All triangle meshes of the
// scene are joined with their node transforms; points and lines are dropped.
// Units: glTF metres; FBX by its header's UnitScaleFactor (centimetres a unit);
// DAE by its <unit> (Assimp applies it); STL and others taken as metres.
// Throws drift::Error naming the file and Assimp's reason.
Mesh read_mesh_assimp(const std::filesystem::path& path, UpAxis up = UpAxis::Auto);

// The extensions read_mesh takes, for messages ("*.3ds;*.dae;...").
std::string mesh_read_extensions();

// Writes by extension: .ply, .obj (z up, as write_obj), .glb/.gltf (write_gltf),
// .stl (write_stl), .fbx (write_fbx). Anything else is a drift::Error naming the
// path and the extensions it takes. Written atomically.
void write_mesh(const Mesh& mesh, const std::filesystem::path& path);
// True if write_mesh takes the extension of `path`.
bool is_mesh_output(const std::filesystem::path& path);

// Memory a mesh of `vertices`, `triangles` and `attributes` named per-vertex
// floats holds (positions, normals, triangles, attributes), plus what
// write_mesh to `path` allocates on top (by extension: PLY and OBJ stream; GLB
// builds its buffers and the file in memory, .gltf also their base64 text; STL
// its file; FBX goes through Assimp's exporter). For the memory checks of the
// commands that build and write meshes (issue 34, class 2): measured within
// 10 % on drift mesh (tests/pipeline/memory_estimate_test.cpp).
std::uint64_t mesh_and_write_bytes(const std::filesystem::path& path, std::uint64_t vertices,
                                   std::uint64_t triangles, std::size_t attributes);

// glTF 2.0: binary GLB for .glb, JSON with the buffer embedded as a data URI
// for .gltf. Metres, y up as glTF requires: drift's (x, y, z) is written as
// (x, z, -y), a rotation, so windings stay counter-clockwise. NORMAL always
// (area-weighted vertex normals when the mesh has none); each named attribute
// as a custom vertex attribute "_NAME" (upper case, e.g. "_SNOW_COVERAGE");
// the origin in the CRS in the asset's extras ("drift_origin").
void write_gltf(const Mesh& mesh, const std::filesystem::path& path);

// Reads a GLB directly (terrain/mesh_glb.cpp), keeping what Assimp 5.2 drops
// (assimp#4830): custom vertex attributes "_NAME" as attributes "name"
// (write_gltf's "_SNOW_COVERAGE" -> "snow_coverage") and the origin in
// asset.extras.drift_origin. Takes GLBs of the form write_gltf writes:
// triangle primitives (joined), float POSITION, NORMAL and SCALAR custom
// attributes, unsigned byte/short/int indices, buffer 0 the BIN chunk, no
// node transforms, sparse accessors, interleaving or required extensions.
// y up back to z up ((x, y, z) -> (x, -z, y), write_gltf's inverse, exact).
// Every chunk length, offset, stride and count is checked against the file
// before use; anything else is a drift::Error naming the file and the value.
Mesh read_glb(const std::filesystem::path& path);

// Binary STL: facets with their normals, z up and metres as stored (STL says
// neither; docs/meshes.md).
void write_stl(const Mesh& mesh, const std::filesystem::path& path);

// ASCII FBX 7.5 through Assimp's exporter (its binary writer of Debian's 5.2
// writes files that Assimp itself cannot read back): y up, in centimetres, the
// unit FBX's header declares (UnitScaleFactor 1), so Blender and Maya place it
// in metres.
void write_fbx(const Mesh& mesh, const std::filesystem::path& path);

// Area-weighted vertex normals (unit length; a vertex of no area gets +z).
std::vector<Eigen::Vector3f> vertex_normals(const Mesh& mesh);

}  // namespace drift::terrain
