// A triangle mesh: the plain data type for objects (rocks, trees, huts, feet,
// wheels) and for surfaces the stages produce (snowy meshes, soil surfaces).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace drift::terrain {

struct Mesh {
  std::vector<Eigen::Vector3f> positions;     // metres, x east, y north, z up
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
  std::vector<Eigen::Vector3f> normals;       // per vertex, optional (empty or = positions)
  // Named per-vertex scalar attributes (e.g. "snow_depth", "snow_coverage").
  std::vector<std::pair<std::string, std::vector<float>>> vertex_attributes;
  // Where the mesh's coordinates are measured from, in a CRS (float positions
  // cannot hold UTM-sized numbers to the centimetre). Kept in PLY files.
  Eigen::Vector3d origin{0, 0, 0};

  // The named per-vertex attribute, or nullptr.
  const std::vector<float>* attribute(const std::string& name) const {
    for (const auto& [n, v] : vertex_attributes)
      if (n == name) return &v;
    return nullptr;
  }

  std::size_t vertex_count() const { return positions.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
};

// An object as a scene places it (rocks, trees, huts): what snow falls on and
// the renderer traces. Its mesh's attributes are products (terrain/products.h):
// the snowy objects of drift snow fall carry their snow coverage.
struct PlacedMesh {
  Mesh mesh;  // in its own frame (metres), already rotated and scaled
  // Where the mesh's origin stands, in the raster's CRS. Kept in double: UTM
  // coordinates in float would lose half a metre.
  Eigen::Vector3d position{0, 0, 0};
  Eigen::Vector3f albedo{0.5f, 0.5f, 0.5f};
  // The renderer's material preset (render/material.h) the object is made of,
  // with `albedo` as its albedo; empty: plain diffuse `albedo`.
  std::string material;
};

}  // namespace drift::terrain
