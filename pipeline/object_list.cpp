#include "pipeline/object_list.h"

#include <cmath>

#include "pipeline/toml_section.h"
#include "terrain/angles.h"
#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/mesh_io.h"

namespace drift::pipeline {

namespace fs = std::filesystem;

namespace {

// An entry's mesh: relative paths are relative to the file naming them.
fs::path mesh_path(const fs::path& file, const std::string& mesh) {
  return fs::path(mesh).is_absolute() ? fs::path(mesh) : file.parent_path() / mesh;
}

}  // namespace

std::vector<terrain::PlacedMesh> read_objects(const toml::table& root, const fs::path& file,
                                              const ObjectKeys& extra) {
  std::vector<terrain::PlacedMesh> out;
  if (const toml::node* objects = root.get("objects")) {
    const toml::array* list = objects->as_array();
    if (!list) throw Error(file.string() + ": 'objects' must be an array of tables ([[objects]])");
    for (const toml::node& entry : *list) {
      if (!entry.is_table())
        throw Error(file.string() + ": every [[objects]] entry must be a table");
      Section obj(entry.as_table(), "objects", file);
      const auto mesh = obj.string("mesh");
      if (!mesh)
        throw Error(file.string() +
                    ": an [[objects]] entry needs 'mesh' (a glTF/GLB, FBX, STL, OBJ or PLY file)");
      // Unset: the format says which way is up (glTF y, FBX its header, others z).
      const terrain::UpAxis up = !obj.has("y_up")             ? terrain::UpAxis::Auto
                                 : obj.boolean("y_up", false) ? terrain::UpAxis::Y
                                                              : terrain::UpAxis::Z;
      const auto position = obj.vector<3>("position", -1e8, 1e8);
      const double scale = obj.number("scale", 1.0, 1e-6, 1e6);
      const double rotate = obj.number("rotate_z", 0.0, -360.0, 360.0);
      terrain::PlacedMesh placed;
      placed.albedo = obj.color("color", placed.albedo);
      if (extra) extra(obj, out.size());
      obj.finish();
      placed.mesh = terrain::read_mesh(mesh_path(file, *mesh), up);
      const double a = terrain::radians(rotate);
      placed.position = position ? *position : Eigen::Vector3d::Zero();
      for (auto& p : placed.mesh.positions) {
        const double x = p.x() * scale, y = p.y() * scale, z = p.z() * scale;
        p = Eigen::Vector3f(static_cast<float>(std::cos(a) * x - std::sin(a) * y),
                            static_cast<float>(std::sin(a) * x + std::cos(a) * y),
                            static_cast<float>(z));
      }
      for (auto& n : placed.mesh.normals)  // a glTF's or FBX's normals turn with it
        n = Eigen::Vector3f(static_cast<float>(std::cos(a) * n.x() - std::sin(a) * n.y()),
                            static_cast<float>(std::sin(a) * n.x() + std::cos(a) * n.y()), n.z());
      out.push_back(std::move(placed));
    }
  }
  return out;
}

std::vector<terrain::PlacedMesh> read_objects_file(const fs::path& path) {
  const toml::table root = parse_toml_file(path, "objects file");
  for (const auto& [k, node] : root) {
    if (k.str() != "objects") {
      throw Error(path.string() + ":" + std::to_string(node.source().begin.line) +
                  ": unknown section '" + std::string(k.str()) +
                  "' (an objects file holds only [[objects]] entries)");
    }
  }
  return read_objects(root, path);
}

std::vector<fs::path> object_mesh_paths(const fs::path& path, const char* what) {
  return object_mesh_paths(parse_toml_file(path, what), path);
}

std::vector<fs::path> object_mesh_paths(const toml::table& root, const fs::path& path) {
  std::vector<fs::path> meshes;
  if (const toml::array* list = root["objects"].as_array()) {
    for (const toml::node& entry : *list) {
      const toml::table* t = entry.as_table();
      const toml::node* mesh = t ? t->get("mesh") : nullptr;
      if (mesh && mesh->is_string()) meshes.push_back(mesh_path(path, **mesh->as_string()));
    }
  }
  return meshes;
}

void require_metric_crs(const terrain::HeightField& raster, const fs::path& path) {
  if (terrain::is_geographic(raster.geo().crs_wkt)) {
    throw Error("raster '" + path.string() +
                "' is in degrees (geographic CRS); convert it to metres first: drift import " +
                path.string() + " -o DEM_metric.tif");
  }
}

}  // namespace drift::pipeline
