#include "pipeline/scene_file.h"

#include <toml++/toml.h>

#include <cmath>
#include <set>

#include "pipeline/object_list.h"
#include "pipeline/toml_section.h"
#include "terrain/error.h"
#include "terrain/raster_io.h"

namespace drift::pipeline {

namespace fs = std::filesystem;

namespace {

const toml::table* subtable(const toml::table& root, const char* name, const fs::path& file) {
  const toml::node* node = root.get(name);
  if (!node) return nullptr;
  if (!node->is_table()) {
    throw Error(file.string() + ": '" + name + "' must be a table ([" + name + "])");
  }
  return node->as_table();
}

}  // namespace

SceneFile read_scene_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw Error("cannot read scene '" + path.string() + "': no such file");
  toml::table root;
  try {
    root = toml::parse_file(path.string());
  } catch (const toml::parse_error& e) {
    throw Error(path.string() + ":" + std::to_string(e.source().begin.line) +
                ": TOML syntax error: " + std::string(e.description()));
  }
  static const std::set<std::string> sections = {"terrain", "sun",    "sky",    "camera",
                                                 "render",  "output", "objects"};
  for (const auto& [k, node] : root) {
    if (!sections.count(std::string(k.str()))) {
      throw Error(path.string() + ":" + std::to_string(node.source().begin.line) +
                  ": unknown section '" + std::string(k.str()) +
                  "' (known: terrain, sun, sky, camera, objects, render, output)");
    }
  }
  const fs::path base = path.parent_path();
  SceneFile scene;
  render::SceneInput& in = scene.input;

  Section terrain(subtable(root, "terrain", path), "terrain", path);
  const auto raster = terrain.string("raster");
  if (!raster) throw Error(path.string() + ": '[terrain] raster' is required (a DEM GeoTIFF)");
  scene.terrain_raster = fs::path(*raster).is_absolute() ? fs::path(*raster) : base / *raster;
  in.vertical_exaggeration = terrain.number("exaggeration", 1.0, 0.01, 100.0);
  in.terrain_albedo = terrain.color("color", in.terrain_albedo);
  terrain.finish();

  Section sun(subtable(root, "sun", path), "sun", path);
  in.sun.azimuth_deg = sun.number("azimuth", in.sun.azimuth_deg, 0.0, 360.0);
  in.sun.elevation_deg = sun.number("elevation", in.sun.elevation_deg, -90.0, 90.0);
  in.sun.angular_diameter_deg =
      sun.number("angular_diameter", in.sun.angular_diameter_deg, 1e-3, 20.0);
  in.sun.irradiance = sun.number("irradiance", in.sun.irradiance, 0.0, 1e6);
  in.sun.color = sun.color("color", in.sun.color);
  sun.finish();

  Section sky(subtable(root, "sky", path), "sky", path);
  in.sky.zenith = sky.color("zenith", in.sky.zenith);
  in.sky.horizon = sky.color("horizon", in.sky.horizon);
  in.sky.intensity = static_cast<float>(sky.number("intensity", in.sky.intensity, 0.0, 1e6));
  in.sky.ground_factor =
      static_cast<float>(sky.number("ground_factor", in.sky.ground_factor, 0.0, 10.0));
  in.sky.constant = sky.boolean("constant", in.sky.constant);
  sky.finish();

  if (const toml::table* cam_table = subtable(root, "camera", path)) {
    Section cam(cam_table, "camera", path);
    render::Camera camera;
    const auto from = cam.vector<3>("from", -1e8, 1e8);
    const auto to = cam.vector<3>("to", -1e8, 1e8);
    camera.vertical_fov_deg = cam.number("fov", camera.vertical_fov_deg, 0.1, 179.0);
    cam.finish();
    if (!from || !to)
      throw Error(path.string() +
                  ": [camera] needs both 'from' and 'to' ([x, y, z] in the raster's CRS, metres)");
    camera.from = *from;
    camera.to = *to;
    in.camera = camera;
  }

  in.meshes = read_objects(root, path);

  Section rs(subtable(root, "render", path), "render", path);
  scene.settings.width = rs.integer("width", scene.settings.width, 1, 16384);
  scene.settings.height = rs.integer("height", scene.settings.height, 1, 16384);
  scene.settings.samples_per_pixel =
      rs.integer("spp", scene.settings.samples_per_pixel, 1, 1 << 20);
  scene.settings.max_depth = rs.integer("max_depth", scene.settings.max_depth, 1, 1024);
  scene.settings.seed = static_cast<std::uint64_t>(rs.integer("seed", 1, 0, 2147483647));
  rs.finish();

  Section out(subtable(root, "output", path), "output", path);
  for (const std::string& f : out.strings("files")) scene.outputs.emplace_back(f);
  scene.display.exposure_ev = out.number("exposure", 0.0, -20.0, 20.0);
  const auto tone = out.string("tone");
  if (tone && *tone != "filmic" && *tone != "clamp") {
    throw Error(path.string() + ": 'output.tone' is '" + *tone + "'; use \"filmic\" or \"clamp\"");
  }
  scene.display.curve =
      (tone && *tone == "clamp") ? render::ToneCurve::Clamp : render::ToneCurve::Filmic;
  out.finish();
  return scene;
}

void load_scene_terrain(SceneFile& scene) {
  scene.input.terrain = terrain::read_raster(scene.terrain_raster);
  require_metric_crs(scene.input.terrain, scene.terrain_raster);
}

}  // namespace drift::pipeline
