#include "pipeline/scene_file.h"

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <regex>
#include <set>

#include "pipeline/object_list.h"
#include "pipeline/scene_products.h"
#include "pipeline/scene_variables.h"
#include "pipeline/toml_section.h"
#include "render/atmosphere.h"
#include "render/land_form.h"
#include "render/material.h"
#include "render/solar_position.h"
#include "render/surface.h"
#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/raster_blocks.h"
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

// [output] exposure: "auto" (the default: metered, render/auto_exposure.h,
// plus `exposure_compensation`) or a fixed number of EV.
void read_exposure(Section& out, const toml::table* table, render::DisplayTransform& display) {
  const toml::node* node = table ? table->get("exposure") : nullptr;
  display.auto_exposure = !node || node->is_string();
  if (node && node->is_string()) {
    const std::string mode = *out.string("exposure");
    if (mode != "auto")
      out.invalid("exposure", "is '" + mode + "'; use \"auto\" or a number of EV");
  } else if (node) {
    display.exposure_ev = out.number("exposure", 0.0, -render::DisplayTransform::kMaxEv,
                                     render::DisplayTransform::kMaxEv);
  }
  const double compensation =
      out.number("exposure_compensation", 0.0, -render::DisplayTransform::kMaxEv,
                 render::DisplayTransform::kMaxEv);
  if (compensation != 0.0 && !display.auto_exposure)
    out.invalid("exposure_compensation",
                "needs exposure = \"auto\"; with a fixed exposure set that instead");
  if (display.auto_exposure) display.exposure_ev = compensation;
}

// The detail keys of a material (render/ground_detail.h): `variation`,
// `bump`, `bump_scale`, each over the preset's (or none).
void read_detail(Section& s, render::MaterialOverride& m) {
  const double variation = s.number("variation", -1.0, 0.0, 1.0);
  const double bump = s.number("bump", -1.0, 0.0, 2.0);
  const double scale = s.number("bump_scale", -1.0, 0.01, 100.0);
  if (variation < 0.0 && bump < 0.0 && scale < 0.0) return;
  render::GroundDetail d = m.detail.value_or(render::GroundDetail{});
  if (variation >= 0.0) d.variation = static_cast<float>(variation);
  if (bump >= 0.0) d.bump = static_cast<float>(bump);
  if (scale >= 0.0) d.scale = static_cast<float>(scale);
  m.detail = d;
}

// `material`: a preset's name (render/material.h), checked; empty without one.
std::string read_preset_name(Section& s) {
  const auto name = s.string("material");
  if (!name) return {};
  if (!render::material_preset(*name))
    s.invalid("material",
              "is '" + *name + "'; known materials: " + render::material_preset_names());
  return *name;
}

// The material keys of [terrain], [[terrain.rule]] and [[terrain.layer]]:
// `material` names a preset (which sets every field), and `color`,
// `roughness` and `wetness` set (or override) one field each. `preset` gets
// the preset's name (empty without one).
render::MaterialOverride read_material(Section& s, std::string& preset) {
  render::MaterialOverride m;
  preset = read_preset_name(s);
  if (!preset.empty()) m = render::full_override(*render::material_preset(preset));
  const Eigen::Vector3f none = Eigen::Vector3f::Constant(-1.0f);
  if (const Eigen::Vector3f c = s.color("color", none); c != none) m.albedo = c;
  if (const double r = s.number("roughness", -1.0, 0.0, render::kMaxRoughness); r >= 0.0)
    m.roughness = static_cast<float>(r);
  if (const double w = s.number("wetness", -1.0, 0.0, 1.0); w >= 0.0)
    m.wetness = static_cast<float>(w);
  read_detail(s, m);
  return m;
}

// A rule or layer must set something.
void require_material(const Section& s, const render::MaterialOverride& m) {
  if (m.empty()) {
    s.invalid_table("sets no material: give 'material' (" + render::material_preset_names() +
                    ") or 'color', 'roughness' or 'wetness'");
  }
}

// The coverage channel of a rule or layer (render/coverage.h), which the
// CryptoMaterial matte names too: `name`, else its preset's name, else the
// fields it sets ("wetness", "color_roughness"), never its index: a name
// says what the mask is in a compositor. `fallback` only for what sets
// none of them (detail alone).
std::string coverage_name(Section& s, const std::string& preset, const render::MaterialOverride& m,
                          const std::string& fallback) {
  const auto name = s.string("name");
  if (!name) {
    if (!preset.empty()) return preset;
    std::string fields;
    auto add = [&](bool set, const char* field) {
      if (set) fields.append(fields.empty() ? "" : "_").append(field);
    };
    add(m.albedo.has_value(), "color");
    add(m.roughness.has_value(), "roughness");
    add(m.wetness.has_value(), "wetness");
    return fields.empty() ? fallback : fields;
  }
  static const std::regex word("[A-Za-z0-9_-]{1,32}");
  if (!std::regex_match(*name, word)) {
    s.invalid("name", "is '" + *name + "'; use 1-32 letters, digits, '_' or '-' (it names the " +
                          "EXR channel coverage.<name>)");
  }
  return *name;
}

// One side of a rule: `<name>_min`, `<name>_max` (open when absent) and the
// width of the soft band at each edge, `<name>_blend`.
render::SoftRange read_range(Section& s, const std::string& name, double lo, double hi,
                             double blend) {
  render::SoftRange r;
  const std::string min_key = name + "_min", max_key = name + "_max", blend_key = name + "_blend";
  const double inf = std::numeric_limits<double>::infinity();
  const double a = s.number(min_key.c_str(), -inf, lo, hi);
  const double b = s.number(max_key.c_str(), inf, lo, hi);
  if (!(a < b)) s.invalid(max_key.c_str(), "must be above '" + min_key + "'");
  r.lo = static_cast<float>(a);
  r.hi = static_cast<float>(b);
  r.band = static_cast<float>(s.number(blend_key.c_str(), blend, 0.0, hi - lo));
  return r;
}

// [[terrain.rule]]: a material by altitude and slope (docs/rendering.md).
render::MaterialRule read_rule(const toml::table* table, const fs::path& file, std::size_t index) {
  Section s(table, "terrain.rule", file);
  render::MaterialRule rule;
  std::string preset;
  rule.material = read_material(s, preset);
  rule.name = coverage_name(s, preset, rule.material, "rule" + std::to_string(index + 1));
  rule.altitude = read_range(s, "altitude", -1e4, 1e5, 100.0);
  rule.slope = read_range(s, "slope", 0.0, 90.0, 5.0);
  rule.position = read_range(s, "position", -5000.0, 5000.0, 10.0);
  rule.altitude_jitter = static_cast<float>(s.number("altitude_jitter", 0.0, 0.0, 5000.0));
  rule.opacity = static_cast<float>(s.number("opacity", 1.0, 0.0, 1.0));
  rule.clump_size = static_cast<float>(s.number("clump_size", 0.0, 0.0, 1e4));
  rule.clump_cover = static_cast<float>(s.number("clump_cover", 1.0, 0.0, 1.0));
  rule.patch_size = static_cast<float>(s.number("patch_size", 0.0, 0.0, 1e4));
  s.finish();
  require_material(s, rule.material);
  return rule;
}

// [[terrain.layer]]: a material placed by a mask raster; the mask is read by
// load_scene_terrain.
render::MaterialLayer read_layer(const toml::table* table, const fs::path& file, std::size_t index,
                                 fs::path& mask) {
  Section s(table, "terrain.layer", file);
  render::MaterialLayer layer;
  const auto mask_file = s.string("mask");
  std::string preset;
  layer.material = read_material(s, preset);
  layer.name = coverage_name(s, preset, layer.material, "layer" + std::to_string(index + 1));
  layer.opacity = static_cast<float>(s.number("opacity", 1.0, 0.0, 1.0));
  // Snow shows a partial mask as flakes, as snow cover does (render/surface.h).
  layer.flakes = s.boolean("flakes", preset == "snow");
  s.finish();
  if (!mask_file) s.invalid_table("needs 'mask' (a raster in [0, 1] in the DEM's CRS)");
  require_material(s, layer.material);
  mask =
      fs::path(*mask_file).is_absolute() ? fs::path(*mask_file) : file.parent_path() / *mask_file;
  return layer;
}

// Every top-level key must be a known section.
void check_sections(const toml::table& root, const fs::path& path) {
  const std::vector<std::string> sections = scene_sections();
  for (const auto& [k, node] : root) {
    const std::string key(k.str());
    if (std::find(sections.begin(), sections.end(), key) != sections.end()) continue;
    std::string message = path.string() + ":" + std::to_string(node.source().begin.line);
    message.append(": unknown section '").append(key).append("' (known: ");
    for (std::size_t i = 0; i < sections.size(); ++i)
      message.append(i ? ", " : "").append(sections[i]);
    throw Error(message + ")");
  }
}

// A path in the scene file, relative to the scene file's folder.
fs::path resolve(const fs::path& scene_path, const std::string& p) {
  return fs::path(p).is_absolute() ? fs::path(p) : scene_path.parent_path() / p;
}

// [terrain] surround (rasters), surround_reach and surround_blend: the
// ground beyond the DEM's edge (render/surround.h).
void read_surround(Section& terrain, const fs::path& path, SceneFile& scene) {
  for (const std::string& f : terrain.strings("surround"))
    scene.surround_rasters.push_back(resolve(path, f));
  render::SurroundOptions& o = scene.input.surround;
  o.reach = terrain.number("surround_reach", o.reach, 0.0, 1e6);
  o.blend = terrain.number("surround_blend", o.blend, 0.0, 1e5);
}

// [terrain]: the DEM, its ground material, rules and layers. Returns the
// objects file it names, if any.
std::optional<fs::path> read_terrain(const toml::table& root, const fs::path& path,
                                     SceneFile& scene) {
  render::SceneInput& in = scene.input;
  Section terrain(subtable(root, "terrain", path), "terrain", path);
  const auto raster = terrain.string("raster");
  if (!raster) terrain.invalid_table("needs 'raster' (a DEM GeoTIFF)");
  scene.terrain_raster = resolve(path, *raster);
  in.vertical_exaggeration = terrain.number("exaggeration", 1.0, 0.01, 100.0);
  scene.terrain_repeat = terrain.integer("repeat", 1, 1, 9);
  if (scene.terrain_repeat % 2 == 0)
    terrain.invalid("repeat", "must be odd (the raster stays in the middle)");
  scene.position_radius = terrain.number("position_radius", scene.position_radius, 1.0, 1e5);
  read_surround(terrain, path, scene);
  if (const auto map = terrain.string("albedo_map")) scene.albedo_map = resolve(path, *map);
  // Objects standing on the terrain from an objects file (as `drift snow fall
  // --objects` reads), in addition to any [[objects]] here.
  std::optional<fs::path> objects_file;
  if (const auto file = terrain.string("objects")) objects_file = resolve(path, *file);
  std::string ground_preset;
  in.surface.ground = render::blend(in.surface.ground, read_material(terrain, ground_preset), 1.0f);
  if (!ground_preset.empty()) in.surface.ground_name = ground_preset;
  for (const toml::table* rule : terrain.tables("rule"))
    in.surface.rules.push_back(read_rule(rule, path, in.surface.rules.size()));
  for (const toml::table* layer : terrain.tables("layer")) {
    in.surface.layers.push_back(
        read_layer(layer, path, in.surface.layers.size(), scene.layer_masks.emplace_back()));
  }
  terrain.finish();
  return objects_file;
}

// A stage's section (pipeline/scene_products.h): its product files, then its
// own keys; keeps what loads its products.
void read_stage_section(const toml::table& root, const fs::path& path, const StageSection& stage,
                        SceneFile& scene) {
  Section section(subtable(root, stage.name, path), stage.name, path);
  for (const ProductFileKey& file : stage.files) {
    if (const auto name = section.string(file.key))
      scene.product_files[product_key(stage, file)] = resolve(path, *name);
  }
  if (SceneFile::Loader load = stage.read(section, scene))
    scene.product_loaders.emplace_back(stage.name, std::move(load));
  section.finish();
}

// [sun]: by azimuth and elevation, or by date and time over the DEM.
void read_sun(const toml::table& root, const fs::path& path, SceneFile& scene) {
  render::Sun& s = scene.input.sun;
  Section sun(subtable(root, "sun", path), "sun", path);
  const bool placed = sun.has("azimuth") || sun.has("elevation");
  s.azimuth_deg = sun.number("azimuth", s.azimuth_deg, 0.0, 360.0);
  s.elevation_deg = sun.number("elevation", s.elevation_deg, -90.0, 90.0);
  s.angular_diameter_deg = sun.number("angular_diameter", s.angular_diameter_deg, 1e-3, 20.0);
  s.irradiance = sun.number("irradiance", s.irradiance, 0.0, 1e6);
  s.color = sun.color("color", s.color);
  const auto date = sun.string("date"), time = sun.string("time"), zone = sun.string("timezone");
  sun.finish();
  if (!date && !time && !zone) return;
  if (!date || !time) {
    sun.invalid_table(
        "needs both 'date' (\"YYYY-MM-DD\") and 'time' (\"HH:MM\"), with 'timezone' as a UTC "
        "offset (\"+09:00\", default UTC)");
  }
  if (placed) sun.invalid_table("gives both a date/time and azimuth/elevation; give one");
  try {
    scene.sun_time = render::parse_local_time(*date, *time, zone.value_or("UTC"));
  } catch (const Error& e) {
    sun.invalid_table(e.what());
  }
}

// [sky]: the physical atmosphere (haze or visibility, light shafts) or the
// simple gradient.
void read_sky(const toml::table& root, const fs::path& path, render::Sky& sky_out) {
  Section sky(subtable(root, "sky", path), "sky", path);
  if (const auto model = sky.string("model")) {
    if (*model == "physical") {
      sky_out.model = render::SkyModel::Physical;
    } else if (*model == "simple") {
      sky_out.model = render::SkyModel::Simple;
    } else {
      sky.invalid(
          "model",
          "is '" + *model + "'; use \"physical\" (an Earth atmosphere) or \"simple\" (a gradient)");
    }
  }
  if (sky.has("visibility") && sky.has("haze"))
    sky.invalid("visibility", "and 'sky.haze' are both given: give haze or visibility, not both");
  sky_out.haze = static_cast<float>(sky.number("haze", sky_out.haze, 0.0, 1000.0));
  if (sky.has("visibility")) {
    const double km = sky.number("visibility", 0.0, 1.0, 1000.0);
    try {
      sky_out.haze = static_cast<float>(render::Atmosphere::aerosol_scale_for_visibility(km));
    } catch (const Error& e) {
      sky.invalid("visibility", e.what());
    }
  }
  sky_out.zenith = sky.color("zenith", sky_out.zenith);
  sky_out.horizon = sky.color("horizon", sky_out.horizon);
  sky_out.intensity = static_cast<float>(sky.number("intensity", sky_out.intensity, 0.0, 1e6));
  sky_out.ground_factor =
      static_cast<float>(sky.number("ground_factor", sky_out.ground_factor, 0.0, 10.0));
  sky_out.constant = sky.boolean("constant", sky_out.constant);
  sky_out.light_shafts = sky.boolean("light_shafts", sky_out.light_shafts);
  sky_out.shaft_steps = sky.integer("shaft_steps", sky_out.shaft_steps, 1, 1024);
  sky.finish();
}

// [clouds]: a cloud layer (render/clouds.h), there when the section is; it
// needs the physical sky.
void read_clouds(const toml::table& root, const fs::path& path, render::SceneInput& in) {
  const toml::table* table = subtable(root, "clouds", path);
  if (!table) return;
  Section c(table, "clouds", path);
  render::CloudOptions& o = in.clouds;
  o.enabled = true;
  o.coverage = c.number("coverage", o.coverage, 0.0, 1.0);
  o.density = c.number("density", o.density, 0.0, 500.0);
  o.altitude = c.number("altitude", o.altitude, 0.0, 20000.0);
  o.thickness = c.number("thickness", o.thickness, 1.0, 5000.0);
  o.scale = c.number("scale", o.scale, 50.0, 1e5);
  o.seed = c.seed("seed", o.seed);
  c.finish();
  if (in.sky.model != render::SkyModel::Physical || in.sky.constant) {
    c.invalid_table(
        "needs the physical sky, which lights the clouds: remove [sky] model = \"simple\" and "
        "constant = true, or remove [clouds]");
  }
}

// [camera]'s lens: a field of view, or a focal length with an optional
// aperture for depth of field.
void read_lens(Section& cam, render::Camera& camera) {
  camera.vertical_fov_deg = cam.number("fov", camera.vertical_fov_deg, 0.1, 179.0);
  if (const double f = cam.number("focal_length", 0.0, 0.0, 1e5); f > 0.0)
    camera.focal_length_mm = f;
  camera.sensor_width_mm = cam.number("sensor_width", camera.sensor_width_mm, 0.1, 1000.0);
  camera.f_number = cam.number("f_number", 0.0, 0.0, 1000.0);
  if (const double d = cam.number("focus_distance", 0.0, 0.0, 1e8); d > 0.0)
    camera.focus_distance = d;
  if (camera.f_number > 0.0 && !camera.focal_length_mm)
    cam.invalid("f_number", "needs 'camera.focal_length' (millimetres)");
  // Given values must keep their reciprocals finite (0 means not given).
  if (camera.focal_length_mm && *camera.focal_length_mm < 0.1)
    cam.invalid("focal_length", "must be 0 (none) or at least 0.1 mm");
  if (camera.f_number > 0.0 && camera.f_number < 0.5)
    cam.invalid("f_number", "must be 0 (a pinhole) or at least 0.5");
  if (camera.focus_distance && *camera.focus_distance < 1e-3)
    cam.invalid("focus_distance", "must be 0 (automatic) or at least 0.001 m");
}

// [[camera.keyframe]] entries, in increasing time; `fov` defaults to the
// camera's.
std::vector<KeyframeSpec> read_keyframes(Section& cam, const fs::path& path, double fov) {
  std::vector<KeyframeSpec> keys;
  for (const toml::table* table : cam.tables("keyframe")) {
    Section k(table, "camera.keyframe", path);
    KeyframeSpec key;
    if (!k.has("time")) k.invalid_table("needs 'time' (seconds along the path)");
    key.time = k.number("time", 0.0, -1e9, 1e9);
    key.from = k.vector<3>("from", -1e8, 1e8);
    key.to = k.vector<3>("to", -1e8, 1e8);
    const auto from_ll = k.vector<2>("from_lonlat", -180.0, 180.0);
    const auto to_ll = k.vector<2>("to_lonlat", -180.0, 180.0);
    const double from_height = k.number("from_height", 2.0, -1e4, 1e6);
    const double to_height = k.number("to_height", 0.0, -1e4, 1e6);
    key.fov_deg = k.number("fov", fov, 0.1, 179.0);
    k.finish();
    if (from_ll) key.from_lonlat = GeoPoint{(*from_ll)[0], (*from_ll)[1], from_height};
    if (to_ll) key.to_lonlat = GeoPoint{(*to_ll)[0], (*to_ll)[1], to_height};
    if (!!key.from == !!key.from_lonlat || !!key.to == !!key.to_lonlat)
      k.invalid_table("needs one of 'from' / 'from_lonlat' and one of 'to' / 'to_lonlat'");
    if (!keys.empty() && !(key.time > keys.back().time))
      k.invalid("time", "must be later than the keyframe before's (" +
                            std::to_string(keys.back().time) + ")");
    keys.push_back(key);
  }
  return keys;
}

// [camera]: where it stands and looks (CRS points, or lon/lat placed on the
// DEM by load_scene_terrain) and its lens.
void read_camera(const toml::table& root, const fs::path& path, SceneFile& scene) {
  const toml::table* cam_table = subtable(root, "camera", path);
  if (!cam_table) return;
  Section cam(cam_table, "camera", path);
  render::Camera camera;
  const std::string projection = cam.string("projection").value_or("perspective");
  if (projection != "perspective" && projection != "map") {
    cam.invalid("projection", "is '" + projection +
                                  "'; use \"perspective\" (a view) or \"map\" (straight down, "
                                  "georeferenced)");
  }
  const auto box = cam.vector<4>("map_box", -1e8, 1e8);
  const double cell = cam.number("cell", 0.0, 0.0, 1e6);
  const auto from = cam.vector<3>("from", -1e8, 1e8);
  const auto to = cam.vector<3>("to", -1e8, 1e8);
  const auto from_lonlat = cam.vector<2>("from_lonlat", -180.0, 180.0);
  const auto to_lonlat = cam.vector<2>("to_lonlat", -180.0, 180.0);
  const double from_height = cam.number("from_height", 2.0, -1e4, 1e6);
  const double to_height = cam.number("to_height", 0.0, -1e4, 1e6);
  read_lens(cam, camera);
  scene.keyframes = read_keyframes(cam, path, camera.vertical_fov_deg);
  cam.finish();
  if (!scene.keyframes.empty()) {
    if (projection == "map" || from || to || from_lonlat || to_lonlat)
      cam.invalid_table("has keyframes: give the camera's ends in them, not 'from'/'to'");
    scene.input.camera = camera;  // the lens; placed by load_scene_terrain
    return;
  }
  if (projection == "map") {
    if (from || to || from_lonlat || to_lonlat)
      cam.invalid_table("is a map (straight down): give 'map_box' and 'cell', not 'from'/'to'");
    if (box && (!((*box)[2] > (*box)[0]) || !((*box)[3] > (*box)[1])))
      cam.invalid("map_box", "must be [west, south, east, north] with east > west, north > south");
    scene.map = MapRequest{
        box ? std::optional(std::array<double, 4>{(*box)[0], (*box)[1], (*box)[2], (*box)[3]})
            : std::nullopt,
        cell};
    return;
  }
  if (box || cell > 0.0)
    cam.invalid_table("gives 'map_box' or 'cell' without projection = \"map\"");
  if (from_lonlat && std::fabs((*from_lonlat)[1]) > 90.0)
    cam.invalid("from_lonlat", "has a latitude off the globe; latitudes lie in [-90, 90]");
  if (to_lonlat && std::fabs((*to_lonlat)[1]) > 90.0)
    cam.invalid("to_lonlat", "has a latitude off the globe; latitudes lie in [-90, 90]");
  if (from && from_lonlat) cam.invalid_table("has both 'from' and 'from_lonlat'; give one");
  if (to && to_lonlat) cam.invalid_table("has both 'to' and 'to_lonlat'; give one");
  if (!(from || from_lonlat) || !(to || to_lonlat)) {
    cam.invalid_table(
        "needs where it stands ('from' = [x, y, z] in the raster's CRS, or 'from_lonlat' = "
        "[lon, lat]) and where it looks ('to' or 'to_lonlat')");
  }
  auto geo_point = [](const Eigen::Vector2d& ll, double h) { return GeoPoint{ll[0], ll[1], h}; };
  if (from_lonlat) scene.camera_from_lonlat = geo_point(*from_lonlat, from_height);
  if (to_lonlat) scene.camera_to_lonlat = geo_point(*to_lonlat, to_height);
  if (from) camera.from = *from;
  if (to) camera.to = *to;
  scene.input.camera = camera;  // lon/lat ends are placed by load_scene_terrain
}

// [render]: size, sampling and seed.
void read_render(const toml::table& root, const fs::path& path, render::RenderSettings& settings) {
  Section rs(subtable(root, "render", path), "render", path);
  settings.width = rs.integer("width", settings.width, 1, render::RenderSettings::kMaxSide);
  settings.height = rs.integer("height", settings.height, 1, render::RenderSettings::kMaxSide);
  settings.samples_per_pixel =
      rs.integer("spp", settings.samples_per_pixel, 1, render::RenderSettings::kMaxSamplesPerPixel);
  settings.max_depth = rs.integer("max_depth", settings.max_depth, 1, 1024);
  settings.noise_target =
      static_cast<float>(rs.number("noise_target", settings.noise_target, 0.0, 1.0));
  settings.min_samples =
      rs.integer("min_spp", settings.min_samples, 1, render::RenderSettings::kMaxSamplesPerPixel);
  settings.seed = rs.seed("seed", settings.seed);
  settings.sample_sky = rs.boolean("sample_sky", settings.sample_sky);
  rs.finish();
}

// [output]: files and the PNG's display transform.
void read_output(const toml::table& root, const fs::path& path, SceneFile& scene) {
  Section out(subtable(root, "output", path), "output", path);
  // Relative to the scene file, like every path in it (docs/rendering.md).
  for (const std::string& f : out.strings("files")) scene.outputs.emplace_back(resolve(path, f));
  read_exposure(out, subtable(root, "output", path), scene.display);
  const auto tone = out.string("tone");
  if (tone && *tone != "filmic" && *tone != "clamp")
    out.invalid("tone", "is '" + *tone + "'; use \"filmic\" or \"clamp\"");
  scene.display.curve =
      (tone && *tone == "clamp") ? render::ToneCurve::Clamp : render::ToneCurve::Filmic;
  const std::string balance = out.string("white_balance").value_or("daylight");
  if (balance != "daylight" && balance != "none") {
    out.invalid("white_balance",
                "is '" + balance +
                    "'; use \"daylight\" (the sun 60 degrees up reads white) or \"none\" (sRGB's "
                    "D65)");
  }
  scene.display.white_balance =
      balance == "daylight" ? render::kDaylightWhiteBalance : std::array<float, 3>{1, 1, 1};
  out.finish();
}

// [[objects]] name: the object's matte (render/mattes.h); empty: "object<N>".
std::string read_object_name(Section& s) {
  const auto name = s.string("name");
  if (!name) return {};
  static const std::regex word("[A-Za-z0-9_.-]{1,64}");
  if (!std::regex_match(*name, word))
    s.invalid("name", "is '" + *name + "'; use 1-64 letters, digits, '_', '.' or '-'");
  return *name;
}

// A scene's [[objects]]: the shared keys (pipeline/object_list.h) and
// `material`, a preset (render/material.h) whose albedo `color` overrides.
std::vector<terrain::PlacedMesh> read_objects_with_materials(const toml::table& root,
                                                             const fs::path& path,
                                                             std::vector<std::string>& names) {
  struct Choice {
    std::string preset;
    bool color = false;
    std::string name;
  };
  std::vector<Choice> chosen;
  std::vector<terrain::PlacedMesh> meshes = read_objects(root, path, [&](Section& s, std::size_t) {
    chosen.push_back({read_preset_name(s), s.has("color"), read_object_name(s)});
  });
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    meshes[i].material = chosen[i].preset;
    if (!chosen[i].preset.empty() && !chosen[i].color)
      meshes[i].albedo = render::material_preset(chosen[i].preset)->albedo;
    names.push_back(chosen[i].name);
  }
  return meshes;
}

}  // namespace

SceneFile read_scene_file(const fs::path& path, const SceneVariables& variables) {
  toml::table root = parse_toml_file(path, "scene");
  expand_scene_variables(root, path, variables);
  check_sections(root, path);
  SceneFile scene;
  const std::optional<fs::path> objects_file = read_terrain(root, path, scene);
  for (const StageSection& stage : stage_sections()) read_stage_section(root, path, stage, scene);
  read_sun(root, path, scene);
  read_sky(root, path, scene.input.sky);
  read_clouds(root, path, scene.input);
  read_camera(root, path, scene);
  scene.input.meshes = read_objects_with_materials(root, path, scene.input.object_names);
  scene.object_files = object_mesh_paths(root, path);
  if (objects_file) {
    scene.object_files.push_back(*objects_file);
    for (fs::path& mesh : object_mesh_paths(*objects_file, "objects file"))
      scene.object_files.push_back(std::move(mesh));
    for (auto& placed : read_objects_file(*objects_file))
      scene.input.meshes.push_back(std::move(placed));
  }
  // An object's own mesh file may carry attributes (a PLY a stage wrote);
  // only a stage's section ([snow] objects) brings the products it shades by.
  for (terrain::PlacedMesh& placed : scene.input.meshes) placed.mesh.vertex_attributes.clear();
  read_render(root, path, scene.settings);
  read_output(root, path, scene);
  return scene;
}

namespace {

// Puts the sun where it stands over the DEM's centre at the scene's date and
// time (NOAA's algorithm), its azimuth turned from true north to the grid's.
void place_sun(SceneFile& scene) {
  const terrain::HeightField& dem = scene.input.terrain;
  if (dem.geo().crs_wkt.empty()) {
    throw Error("[sun] date/time needs to know where '" + scene.terrain_raster.string() +
                "' lies, but it has no CRS; give [sun] azimuth and elevation instead");
  }
  const auto lonlat = terrain::centre_lonlat(dem.geo(), dem.width(), dem.height());
  const render::SolarPosition sun = render::solar_position(*scene.sun_time, lonlat[1], lonlat[0]);
  // True north turned to the grid's (meridian convergence at the centre).
  const double convergence = terrain::grid_convergence_deg(dem.geo(), dem.width(), dem.height());
  scene.input.sun.azimuth_deg = std::fmod(sun.azimuth_deg + convergence + 720.0, 360.0);
  scene.input.sun.elevation_deg = sun.elevation_deg;
}

// Turns the camera's lon/lat ends into CRS points at their height above the
// (exaggerated) ground, which must be inside the DEM.
Eigen::Vector3d place_geo_point(const SceneFile& scene, const GeoPoint& p, const char* key) {
  const terrain::HeightField& dem = scene.input.terrain;
  {
    const auto xy = terrain::from_lonlat(dem.geo().crs_wkt, p.lon, p.lat);
    const float ground = render::sample_raster(dem, xy[0], xy[1], NAN);
    if (std::isnan(ground)) {
      throw Error("camera '" + std::string(key) + "' = [" + std::to_string(p.lon) + ", " +
                  std::to_string(p.lat) + "] is not on the terrain '" +
                  scene.terrain_raster.string() +
                  "'; pick a point inside it (drift info shows its extent)");
    }
    return Eigen::Vector3d(xy[0], xy[1],
                           ground * scene.input.vertical_exaggeration + p.above_ground);
  }
}

void place_lonlat_camera(SceneFile& scene) {
  auto place = [&](const GeoPoint& p, const char* key) { return place_geo_point(scene, p, key); };
  if (scene.camera_from_lonlat)
    scene.input.camera->from = place(*scene.camera_from_lonlat, "from_lonlat");
  if (scene.camera_to_lonlat) scene.input.camera->to = place(*scene.camera_to_lonlat, "to_lonlat");
}

// True if a rule places its material by topographic position.
bool uses_position(const render::TerrainSurface& surface) {
  for (const render::MaterialRule& rule : surface.rules)
    if (std::isfinite(rule.position.lo) || std::isfinite(rule.position.hi)) return true;
  return false;
}

}  // namespace

// The camera on its path at the scene's time (its first key's by default).
void place_camera_path(SceneFile& scene) {
  std::vector<render::CameraKey> keys;
  for (const KeyframeSpec& k : scene.keyframes) {
    render::CameraKey key;
    key.time = k.time;
    key.from = k.from ? *k.from : place_geo_point(scene, *k.from_lonlat, "keyframe from_lonlat");
    key.to = k.to ? *k.to : place_geo_point(scene, *k.to_lonlat, "keyframe to_lonlat");
    key.fov_deg = k.fov_deg;
    keys.push_back(key);
  }
  scene.input.camera = render::camera_at(keys, scene.time.value_or(keys.front().time),
                                         scene.input.camera.value_or(render::Camera{}));
}

// A map: the box (the DEM's extent by default) in whole cells from its
// north-west corner, the camera straight down over it, and its geotransform.
void place_map(SceneFile& scene) {
  const terrain::HeightField& dem = scene.input.terrain;
  const auto& gt = dem.geo().geotransform;
  const double cell = scene.map->cell > 0.0 ? scene.map->cell : dem.geo().cell_size_x();
  const std::array<double, 4> box = scene.map->box.value_or(std::array<double, 4>{
      gt[0], gt[3] + gt[5] * dem.height(), gt[0] + gt[1] * dem.width(), gt[3]});
  const double columns = std::round((box[2] - box[0]) / cell);
  const double rows = std::round((box[3] - box[1]) / cell);
  constexpr int kMax = render::RenderSettings::kMaxSide;
  if (columns < 1 || rows < 1 || columns > kMax || rows > kMax) {
    // %g: a box of 1e300 m had printed 301 digits (std::to_string's %f).
    const auto g = [](double v) {
      char text[32];
      std::snprintf(text, sizeof text, "%g", v);
      return std::string(text);
    };
    throw Error("the map of " + g(box[2] - box[0]) + " x " + g(box[3] - box[1]) +
                " m at a cell of " + g(cell) + " m would be " + g(columns) + " x " + g(rows) +
                " pixels; give a cell (--cell or [camera] cell) that makes 1.." +
                std::to_string(kMax) + " a side");
  }
  scene.settings.width = static_cast<int>(columns);
  scene.settings.height = static_cast<int>(rows);
  render::Camera camera;
  camera.projection = render::Projection::Map;
  // Whole cells from the north-west corner: the east and south edges move
  // by under half a cell when the box is not a multiple of it.
  camera.map_box = {box[0], box[3] - rows * cell, box[0] + columns * cell, box[3]};
  scene.input.camera = camera;
  scene.map_geotransform = {box[0], cell, 0.0, box[3], 0.0, -cell};
}

void load_scene_terrain(SceneFile& scene) {
  render::TerrainSurface& surface = scene.input.surface;
  if (scene.coarse_terrain_side > 0) {
    if (scene.terrain_repeat > 1)
      throw Error("[terrain] repeat cannot be used out of core (--memory-budget); remove one");
    scene.input.terrain =
        terrain::RasterBlockReader(scene.terrain_raster).read_coarse(scene.coarse_terrain_side);
    require_metric_crs(scene.input.terrain, scene.terrain_raster);
  } else {
    scene.input.terrain = read_metric_raster(scene.terrain_raster);
  }
  if (scene.terrain_repeat > 1) {
    scene.input.terrain = terrain::repeat_periodic(scene.input.terrain, scene.terrain_repeat);
  }
  if (!scene.keyframes.empty()) {
    place_camera_path(scene);
  } else if (scene.map) {
    place_map(scene);
  } else {
    place_lonlat_camera(scene);
  }
  if (scene.sun_time) place_sun(scene);
  if (!scene.albedo_map.empty()) {
    surface.albedo_map = render::read_albedo_map(scene.albedo_map);
    require_metric_crs(surface.albedo_map->front(), scene.albedo_map);
  }
  for (std::size_t i = 0; i < scene.layer_masks.size(); ++i)
    surface.layers[i].mask = read_metric_raster(scene.layer_masks[i]);
  for (const fs::path& f : scene.surround_rasters)
    scene.input.surround.rasters.push_back(read_metric_raster(f));
  if (uses_position(surface))
    surface.position = render::topographic_position(scene.input.terrain, scene.position_radius);
  for (const auto& [section, load] : scene.product_loaders) load(scene);
}

void read_camera_path(const fs::path& path, SceneFile& scene) {
  const toml::table root = parse_toml_file(path, "camera path");
  for (const auto& [k, node] : root) {
    if (k.str() != "camera")
      throw Error(path.string() + ":" + std::to_string(node.source().begin.line) +
                  ": unknown section '" + std::string(k.str()) +
                  "' (a camera path holds only [[camera.keyframe]] entries)");
  }
  Section cam(subtable(root, "camera", path), "camera", path);
  const double fov = scene.input.camera ? scene.input.camera->vertical_fov_deg : 40.0;
  scene.keyframes = read_keyframes(cam, path, fov);
  cam.finish();
  if (scene.keyframes.empty())
    throw Error(path.string() + ": no [[camera.keyframe]] entries; give at least one");
  scene.map.reset();
  scene.camera_from_lonlat.reset();
  scene.camera_to_lonlat.reset();
}

std::vector<fs::path> scene_inputs(const SceneFile& scene) {
  std::vector<fs::path> inputs = {scene.terrain_raster, scene.albedo_map};
  for (const auto& [key, file] : scene.product_files) inputs.push_back(file);
  inputs.insert(inputs.end(), scene.layer_masks.begin(), scene.layer_masks.end());
  inputs.insert(inputs.end(), scene.surround_rasters.begin(), scene.surround_rasters.end());
  inputs.insert(inputs.end(), scene.object_files.begin(), scene.object_files.end());
  std::erase_if(inputs, [](const fs::path& p) { return p.empty(); });
  return inputs;
}

fs::path SceneFile::product_file(const std::string& key) const {
  const auto found = product_files.find(key);
  return found == product_files.end() ? fs::path() : found->second;
}

bool SceneFile::needs_dem_before_scene() const {
  return terrain_repeat > 1 || !keyframes.empty() || map || camera_from_lonlat ||
         camera_to_lonlat || sun_time || uses_position(input.surface) ||
         !product_file("snow.depth").empty();
}

bool SceneFile::loads(const std::string& name) const {
  return std::any_of(product_loaders.begin(), product_loaders.end(),
                     [&](const auto& loader) { return loader.first == name; });
}

std::vector<std::string> scene_sections() {
  // The renderer's own sections around the stages' (read in this order).
  std::vector<std::string> sections = {"terrain"};
  for (const StageSection& stage : stage_sections()) sections.emplace_back(stage.name);
  for (const char* own : {"sun", "sky", "clouds", "camera", "objects", "render", "output"})
    sections.emplace_back(own);
  return sections;
}

}  // namespace drift::pipeline
