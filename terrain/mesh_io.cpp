#include "terrain/mesh_io.h"

#include <tiny_obj_loader.h>

#include <cmath>
#include <fstream>
#include <system_error>

#include "terrain/atomic_file.h"
#include "terrain/error.h"

namespace drift::terrain {

namespace fs = std::filesystem;

Mesh read_obj(const fs::path& path, bool y_up) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw Error("cannot read mesh '" + path.string() + "': no such file");
  }
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path.string(), config)) {
    throw Error("cannot read mesh '" + path.string() + "': " + reader.Error() +
                " (is it a Wavefront OBJ file?)");
  }
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  Mesh mesh;
  const std::size_t n = attrib.vertices.size() / 3;
  mesh.positions.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float x = attrib.vertices[3 * i], y = attrib.vertices[3 * i + 1],
                z = attrib.vertices[3 * i + 2];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      throw Error("mesh '" + path.string() + "': vertex " + std::to_string(i + 1) +
                  " has a non-finite coordinate");
    }
    mesh.positions.emplace_back(y_up ? Eigen::Vector3f(x, -z, y) : Eigen::Vector3f(x, y, z));
  }
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const auto& idx = shape.mesh.indices;
    for (std::size_t f = 0; f + 2 < idx.size(); f += 3) {
      std::array<int, 3> tri{idx[f].vertex_index, idx[f + 1].vertex_index, idx[f + 2].vertex_index};
      for (int v : tri) {
        if (v < 0 || static_cast<std::size_t>(v) >= n) {
          throw Error("mesh '" + path.string() + "': shape '" + shape.name + "' refers to vertex " +
                      std::to_string(v + 1) + " of " + std::to_string(n));
        }
      }
      mesh.triangles.push_back(tri);
    }
  }
  if (mesh.triangles.empty()) {
    throw Error("mesh '" + path.string() + "' has no faces; export it with faces, not points");
  }
  return mesh;
}

void write_ply(const Mesh& mesh, const fs::path& path) {
  if (mesh.triangles.empty()) throw Error("cannot write '" + path.string() + "': empty mesh");
  const bool with_normals = mesh.normals.size() == mesh.positions.size();
  for (const auto& [name, values] : mesh.vertex_attributes) {
    if (values.size() != mesh.positions.size()) {
      throw Error("internal: attribute '" + name + "' has the wrong length for '" + path.string() +
                  "'");
    }
  }
  AtomicFile out(path);
  {
    std::ofstream f(out.temp_path(), std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\ncomment written by Driftscape\n";
    f << "element vertex " << mesh.positions.size() << "\n";
    f << "property float x\nproperty float y\nproperty float z\n";
    if (with_normals) f << "property float nx\nproperty float ny\nproperty float nz\n";
    for (const auto& attribute : mesh.vertex_attributes) {
      f << "property float " << attribute.first << "\n";
    }
    f << "element face " << mesh.triangles.size() << "\n";
    f << "property list uchar int vertex_indices\nend_header\n";
    auto put = [&f](const auto& v) { f.write(reinterpret_cast<const char*>(&v), sizeof v); };
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      for (int k = 0; k < 3; ++k) put(mesh.positions[i][k]);
      if (with_normals) {
        for (int k = 0; k < 3; ++k) put(mesh.normals[i][k]);
      }
      for (const auto& attribute : mesh.vertex_attributes) put(attribute.second[i]);
    }
    for (const auto& tri : mesh.triangles) {
      put(static_cast<unsigned char>(3));
      for (int v : tri) put(v);
    }
    f.flush();
    if (!f) throw Error("cannot write '" + path.string() + "' (disk full?)");
  }
  out.commit();
}

}  // namespace drift::terrain
