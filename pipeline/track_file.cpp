#include "pipeline/track_file.h"

#include <cmath>
#include <cstdint>

#include "pipeline/object_list.h"
#include "pipeline/toml_section.h"
#include "terrain/error.h"

namespace drift::pipeline {

namespace fs = std::filesystem;

namespace {

std::string where(const fs::path& file, const toml::node& node) {
  return file.string() + ":" + std::to_string(node.source().begin.line);
}

marks::Keyframe read_keyframe(const toml::table* table, const fs::path& file) {
  Section k(table, "objects.keyframes", file);
  marks::Keyframe key;
  key.time = k.number("time", std::nan(""), -1e9, 1e9);
  if (std::isnan(key.time)) k.invalid_table("needs 'time' (seconds)");
  const auto position = k.vector<3>("position", -1e8, 1e8);
  if (!position) k.invalid_table("needs 'position' ([x, y, z], metres)");
  key.position = *position;
  const auto ypr = k.vector<3>("rotation", -1e5, 1e5);
  const auto q = k.vector<4>("quaternion", -1e3, 1e3);
  if (ypr && q) k.invalid("quaternion", "and 'rotation' both given; give one");
  if (ypr) key.rotation = marks::rotation_from_ypr((*ypr)[0], (*ypr)[1], (*ypr)[2]);
  if (q) {
    if (q->norm() < 1e-9) k.invalid("quaternion", "is zero; give [w, x, y, z] of a rotation");
    key.rotation = Eigen::Quaterniond((*q)[0], (*q)[1], (*q)[2], (*q)[3]).normalized();
  }
  k.finish();
  return key;
}

marks::Motion read_motion(Section& s) {
  const auto m = s.string("motion");
  if (!m || *m == "sweep") return marks::Motion::Sweep;
  if (*m == "substeps") return marks::Motion::SubSteps;
  if (*m != "place") s.invalid("motion", "is '" + *m + "'; use sweep, substeps or place");
  return marks::Motion::Place;
}

int read_resolution(Section& s) {
  const toml::node* node = s.raw("resolution");
  if (!node) return 1;
  if (node->is_string() && *node->value<std::string>() == "auto") return 0;
  const std::optional<std::int64_t> r =
      node->is_integer() ? node->value<std::int64_t>() : std::nullopt;
  if (!r || (*r != 1 && *r != 2 && *r != 4)) s.invalid("resolution", "must be 1, 2, 4 or \"auto\"");
  return static_cast<int>(*r);
}

void read_camera(const toml::table& root, const fs::path& file, TrackFile& out) {
  const toml::node* node = root.get("camera");
  if (!node) return;
  if (!node->is_table()) throw Error(where(file, *node) + ": 'camera' must be a table ([camera])");
  Section c(node->as_table(), "camera", file);
  marks::MarksCamera cam;
  const auto p = c.vector<3>("position", -1e8, 1e8);
  if (!p) c.invalid_table("needs 'position' ([x, y, z], metres)");
  cam.position = *p;
  cam.fov_deg = c.number("fov", cam.fov_deg, 1e-3, 179.0);
  cam.width_px = c.integer("width", cam.width_px, 1, 1000000);
  c.finish();
  out.camera = cam;
}

}  // namespace

marks::Material read_material_value(const toml::node& node, const fs::path& file,
                                    const std::string& key) {
  if (node.is_string()) {
    const std::string name = *node.value<std::string>();
    const auto m = marks::material_preset(name);
    if (!m) {
      throw Error(where(file, node) + ": '" + key + "' is '" + name +
                  "'; known materials: " + marks::material_preset_names() +
                  " (or a table {preset, theta, alpha, roughness})");
    }
    return *m;
  }
  if (!node.is_table())
    throw Error(where(file, node) + ": '" + key + "' must be a material name or a table");
  Section s(node.as_table(), key, file);
  marks::Material m;
  if (const auto preset = s.string("preset")) {
    const auto p = marks::material_preset(*preset);
    if (!p) s.invalid("preset", "is '" + *preset + "'; known: " + marks::material_preset_names());
    m = *p;
  }
  m.name = s.string("name").value_or(m.name + "*");
  // The ranges are the material's own (terrain/marks/ground_material.h).
  for (const terrain::Parameter<marks::Material>& p : marks::material_parameters()) {
    const double v = s.number(p.key, p.get(m), p.lo, p.hi);
    if (!p.admits(v))
      s.invalid(p.key, "is " + terrain::refused_value(v) + "; it must lie in " + p.range());
    p.set(m, v);
  }
  s.finish();
  return m;
}

TrackFile read_track_file(const fs::path& path) {
  const toml::table root = parse_toml_file(path, "track file");
  TrackFile out;
  for (const auto& [k, node] : root) {
    const std::string key(k.str());
    if (key != "step" && key != "material" && key != "camera" && key != "objects")
      throw Error(
          where(path, node) + ": unknown key '" + key +
          "' (a track file holds step, material, [camera] and [[objects]]; see docs/marks.md)");
  }
  Section top(&root, "track", path);
  out.step = top.number("step", std::nan(""), 1e-6, 3600.0);
  if (std::isnan(out.step))
    throw Error(path.string() + ": a track file needs 'step' (seconds per simulation step)");
  if (const toml::node* m = root.get("material"))
    out.material = read_material_value(*m, path, "material");
  read_camera(root, path, out);
  std::vector<marks::MarkObject> extra;
  const auto placed = read_objects(root, path, [&](Section& s, std::size_t i) {
    marks::MarkObject o;
    o.name = "object " + std::to_string(i + 1);
    if (const toml::node* m = s.raw("material"))
      o.material = read_material_value(*m, path, "objects.material");
    o.motion = read_motion(s);
    o.resolution = read_resolution(s);
    o.follow_ground = s.boolean("follow_ground", false);
    for (const toml::table* k : s.tables("keyframes"))
      o.trajectory.keys.push_back(read_keyframe(k, path));
    if (o.trajectory.keys.empty())
      s.invalid_table("needs keyframes ([[objects.keyframes]] with time and position)");
    extra.push_back(std::move(o));
  });
  if (placed.empty())
    throw Error(path.string() + ": a track file needs at least one [[objects]] entry");
  const std::vector<fs::path> meshes = object_mesh_paths(path, "track file");
  for (std::size_t i = 0; i < placed.size(); ++i) {
    marks::MarkObject& o = extra[i];
    if (i < meshes.size()) o.name += " (" + meshes[i].filename().string() + ")";
    o.mesh = placed[i].mesh;
    for (marks::Keyframe& k : o.trajectory.keys) k.position += placed[i].position;
    o.trajectory.validate(path.string() + ": " + o.name);
    out.objects.push_back(std::move(o));
  }
  return out;
}

}  // namespace drift::pipeline
