#include "pipeline/scene_file.h"

#include <toml++/toml.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <regex>
#include <set>

#include "pipeline/object_list.h"
#include "pipeline/toml_section.h"
#include "render/atmosphere.h"
#include "render/land_form.h"
#include "render/material.h"
#include "render/solar_position.h"
#include "render/surface.h"
#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/mesh_io.h"
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
    if (mode != "auto") out.invalid("exposure", "is '" + mode + "'; use \"auto\" or a number of EV");
  } else if (node) {
    display.exposure_ev = out.number("exposure", 0.0, -20.0, 20.0);
  }
  const double compensation = out.number("exposure_compensation", 0.0, -20.0, 20.0);
  if (compensation != 0.0 && !display.auto_exposure)
    out.invalid("exposure_compensation", "needs exposure = \"auto\"; with a fixed exposure set that instead");
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

// [terrain] surround (rasters), surround_reach and surround_blend: the
// ground beyond the DEM's edge (render/surround.h).
template <class Resolve>
void read_surround(Section& terrain, SceneFile& scene, const Resolve& resolve) {
  for (const std::string& f : terrain.strings("surround"))
    scene.surround_rasters.push_back(resolve(f));
  render::SurroundOptions& o = scene.input.surround;
  o.reach = terrain.number("surround_reach", o.reach, 0.0, 1e6);
  o.blend = terrain.number("surround_blend", o.blend, 0.0, 1e5);
}

// The material keys of [terrain], [[terrain.rule]] and [[terrain.layer]]:
// `material` names a preset (which sets every field), and `color`,
// `roughness` and `wetness` set (or override) one field each. `preset` gets
// the preset's name (empty without one).
render::MaterialOverride read_material(Section& s, std::string& preset) {
  render::MaterialOverride m;
  preset.clear();
  if (const auto name = s.string("material")) {
    preset = *name;
    const auto found = render::material_preset(*name);
    if (!found) {
      s.invalid("material",
                "is '" + *name + "'; known materials: " + render::material_preset_names());
    }
    m = render::full_override(*found);
  }
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

// The coverage channel of a rule or layer (render/coverage.h): `name`, else
// its preset's name, else `fallback`.
std::string coverage_name(Section& s, const std::string& preset, const std::string& fallback) {
  const auto name = s.string("name");
  if (!name) return preset.empty() ? fallback : preset;
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
  rule.name = coverage_name(s, preset, "rule" + std::to_string(index + 1));
  rule.altitude = read_range(s, "altitude", -1e4, 1e5, 100.0);
  rule.slope = read_range(s, "slope", 0.0, 90.0, 5.0);
  rule.position = read_range(s, "position", -5000.0, 5000.0, 10.0);
  rule.altitude_jitter = static_cast<float>(s.number("altitude_jitter", 0.0, 0.0, 5000.0));
  rule.opacity = static_cast<float>(s.number("opacity", 1.0, 0.0, 1.0));
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
  layer.name = coverage_name(s, preset, "layer" + std::to_string(index + 1));
  layer.opacity = static_cast<float>(s.number("opacity", 1.0, 0.0, 1.0));
  s.finish();
  if (!mask_file) s.invalid_table("needs 'mask' (a raster in [0, 1] in the DEM's CRS)");
  require_material(s, layer.material);
  mask =
      fs::path(*mask_file).is_absolute() ? fs::path(*mask_file) : file.parent_path() / *mask_file;
  return layer;
}

}  // namespace

SceneFile read_scene_file(const fs::path& path) {
  const toml::table root = parse_toml_file(path, "scene");
  static const std::set<std::string> sections = {"terrain", "snow",   "ripples", "sun",    "sky",
                                                 "camera",  "render", "output",  "objects"};
  for (const auto& [k, node] : root) {
    if (!sections.count(std::string(k.str()))) {
      throw Error(path.string() + ":" + std::to_string(node.source().begin.line) +
                  ": unknown section '" + std::string(k.str()) +
                  "' (known: terrain, snow, ripples, sun, sky, camera, objects, render, output)");
    }
  }
  const fs::path base = path.parent_path();
  SceneFile scene;
  render::SceneInput& in = scene.input;

  Section terrain(subtable(root, "terrain", path), "terrain", path);
  const auto raster = terrain.string("raster");
  if (!raster) throw Error(path.string() + ": '[terrain] raster' is required (a DEM GeoTIFF)");
  auto resolve = [&](const std::string& p) {
    return fs::path(p).is_absolute() ? fs::path(p) : base / p;
  };
  scene.terrain_raster = resolve(*raster);
  in.vertical_exaggeration = terrain.number("exaggeration", 1.0, 0.01, 100.0);
  scene.terrain_repeat = terrain.integer("repeat", 1, 1, 9);
  scene.position_radius = terrain.number("position_radius", scene.position_radius, 1.0, 1e5);
  read_surround(terrain, scene, resolve);
  if (const auto map = terrain.string("albedo_map")) scene.albedo_map = resolve(*map);
  // Objects standing on the terrain from an objects file (as `drift snow fall
  // --objects` reads), in addition to any [[objects]] here.
  std::optional<fs::path> objects_file;
  if (const auto file = terrain.string("objects")) objects_file = resolve(*file);
  if (scene.terrain_repeat % 2 == 0) {
    throw Error(path.string() + ": 'terrain.repeat' must be odd (the raster stays in the middle)");
  }
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

  Section snow(subtable(root, "snow", path), "snow", path);
  if (const auto cover = snow.string("cover")) scene.snow_cover = resolve(*cover);
  if (const auto depth = snow.string("depth")) scene.snow_depth = resolve(*depth);
  if (const auto objects = snow.string("objects")) scene.snow_objects = resolve(*objects);
  in.surface.snow.albedo = snow.color("color", in.surface.snow.albedo);
  in.surface.snow.roughness = static_cast<float>(
      snow.number("roughness", in.surface.snow.roughness, 0.0, render::kMaxRoughness));
  in.surface.snow.forward_scattering = static_cast<float>(
      snow.number("forward_scattering", in.surface.snow.forward_scattering, 0.0, 1.0));
  in.surface.snow_scattering =
      static_cast<float>(snow.number("scattering", in.surface.snow_scattering, 1.0, 1e5));
  in.surface.snow_cover_outside = static_cast<float>(
      snow.number("cover_outside", in.surface.snow_cover_outside, 0.0, 1.0));
  snow.finish();

  if (const toml::table* ripple_table = subtable(root, "ripples", path)) {
    Section rip(ripple_table, "ripples", path);
    const auto ripple_raster = rip.string("raster");
    if (!ripple_raster)
      throw Error(path.string() + ": [ripples] needs 'raster' (a tileable height field from " +
                  "drift dunes --model ripples)");
    scene.ripples = resolve(*ripple_raster);
    render::RippleLayer layer;
    const double cell = rip.number("cell", 0.0, 0.0, 100.0);
    if (cell > 0.0) scene.ripple_texel_metres = cell;
    layer.rotation_deg = rip.number("rotation", 0.0, -360.0, 360.0);
    layer.strength = static_cast<float>(rip.number("strength", 1.0, 0.0, 100.0));
    const auto fade = rip.vector<2>("fade_slope", 0.0, 90.0);
    if (fade) {
      if (!((*fade)[0] < (*fade)[1]))
        throw Error(path.string() + ": 'ripples.fade_slope' must be [start, end] with start < end");
      layer.fade_start_deg = static_cast<float>((*fade)[0]);
      layer.fade_end_deg = static_cast<float>((*fade)[1]);
    }
    rip.finish();
    in.surface.ripples = std::move(layer);
  }

  Section sun(subtable(root, "sun", path), "sun", path);
  in.sun.azimuth_deg = sun.number("azimuth", in.sun.azimuth_deg, 0.0, 360.0);
  in.sun.elevation_deg = sun.number("elevation", in.sun.elevation_deg, -90.0, 90.0);
  in.sun.angular_diameter_deg =
      sun.number("angular_diameter", in.sun.angular_diameter_deg, 1e-3, 20.0);
  in.sun.irradiance = sun.number("irradiance", in.sun.irradiance, 0.0, 1e6);
  in.sun.color = sun.color("color", in.sun.color);
  const auto date = sun.string("date"), time = sun.string("time"), zone = sun.string("timezone");
  sun.finish();
  if (date || time || zone) {
    if (!date || !time) {
      throw Error(path.string() + ": [sun] needs both 'date' (\"YYYY-MM-DD\") and 'time' " +
                  "(\"HH:MM\"), with 'timezone' as a UTC offset (\"+09:00\", default UTC)");
    }
    const toml::table* table = subtable(root, "sun", path);
    if (table->contains("azimuth") || table->contains("elevation")) {
      throw Error(path.string() + ": [sun] gives both a date/time and azimuth/elevation; give one");
    }
    try {
      scene.sun_time = render::parse_local_time(*date, *time, zone.value_or("UTC"));
    } catch (const Error& e) {
      throw Error(path.string() + ": [sun] " + e.what());
    }
  }

  const toml::table* sky_table = subtable(root, "sky", path);
  Section sky(sky_table, "sky", path);
  if (const auto model = sky.string("model")) {
    if (*model == "physical") {
      in.sky.model = render::SkyModel::Physical;
    } else if (*model == "simple") {
      in.sky.model = render::SkyModel::Simple;
    } else {
      throw Error(path.string() + ": 'sky.model' is '" + *model +
                  "'; use \"physical\" (an Earth atmosphere) or \"simple\" (a gradient)");
    }
  }
  in.sky.haze = static_cast<float>(sky.number("haze", in.sky.haze, 0.0, 1000.0));
  if (sky_table && sky_table->contains("visibility")) {
    if (sky_table->contains("haze"))
      throw Error(path.string() + ": give [sky] haze or visibility, not both");
    const double km = sky.number("visibility", 0.0, 1.0, 1000.0);
    try {
      in.sky.haze = static_cast<float>(render::Atmosphere::aerosol_scale_for_visibility(km));
    } catch (const Error& e) {
      throw Error(path.string() + ": 'sky.visibility': " + e.what());
    }
  }
  in.sky.zenith = sky.color("zenith", in.sky.zenith);
  in.sky.horizon = sky.color("horizon", in.sky.horizon);
  in.sky.intensity = static_cast<float>(sky.number("intensity", in.sky.intensity, 0.0, 1e6));
  in.sky.ground_factor =
      static_cast<float>(sky.number("ground_factor", in.sky.ground_factor, 0.0, 10.0));
  in.sky.constant = sky.boolean("constant", in.sky.constant);
  in.sky.light_shafts = sky.boolean("light_shafts", in.sky.light_shafts);
  in.sky.shaft_steps = sky.integer("shaft_steps", in.sky.shaft_steps, 1, 1024);
  sky.finish();

  if (const toml::table* cam_table = subtable(root, "camera", path)) {
    Section cam(cam_table, "camera", path);
    render::Camera camera;
    const auto from = cam.vector<3>("from", -1e8, 1e8);
    const auto to = cam.vector<3>("to", -1e8, 1e8);
    const auto from_lonlat = cam.vector<2>("from_lonlat", -180.0, 180.0);
    const auto to_lonlat = cam.vector<2>("to_lonlat", -180.0, 180.0);
    const double from_height = cam.number("from_height", 2.0, -1e4, 1e6);
    const double to_height = cam.number("to_height", 0.0, -1e4, 1e6);
    camera.vertical_fov_deg = cam.number("fov", camera.vertical_fov_deg, 0.1, 179.0);
    if (const double f = cam.number("focal_length", 0.0, 0.0, 1e5); f > 0.0)
      camera.focal_length_mm = f;
    camera.sensor_width_mm = cam.number("sensor_width", camera.sensor_width_mm, 0.1, 1000.0);
    camera.f_number = cam.number("f_number", 0.0, 0.0, 1000.0);
    if (const double d = cam.number("focus_distance", 0.0, 0.0, 1e8); d > 0.0)
      camera.focus_distance = d;
    cam.finish();
    if (camera.f_number > 0.0 && !camera.focal_length_mm)
      throw Error(path.string() + ": 'camera.f_number' needs 'camera.focal_length' (millimetres)");
    if (from && from_lonlat)
      throw Error(path.string() + ": [camera] has both 'from' and 'from_lonlat'; give one");
    if (to && to_lonlat)
      throw Error(path.string() + ": [camera] has both 'to' and 'to_lonlat'; give one");
    if (!(from || from_lonlat) || !(to || to_lonlat))
      throw Error(path.string() +
                  ": [camera] needs where it stands ('from' = [x, y, z] in the raster's CRS, or "
                  "'from_lonlat' = [lon, lat]) and where it looks ('to' or 'to_lonlat')");
    auto geo_point = [](const Eigen::Vector2d& ll, double h) { return GeoPoint{ll[0], ll[1], h}; };
    if (from_lonlat) scene.camera_from_lonlat = geo_point(*from_lonlat, from_height);
    if (to_lonlat) scene.camera_to_lonlat = geo_point(*to_lonlat, to_height);
    if (from) camera.from = *from;
    if (to) camera.to = *to;
    in.camera = camera;  // lon/lat ends are placed by load_scene_terrain
  }

  in.meshes = read_objects(root, path);
  if (objects_file) {
    for (auto& placed : read_objects_file(*objects_file)) in.meshes.push_back(std::move(placed));
  }

  Section rs(subtable(root, "render", path), "render", path);
  scene.settings.width = rs.integer("width", scene.settings.width, 1, 16384);
  scene.settings.height = rs.integer("height", scene.settings.height, 1, 16384);
  scene.settings.samples_per_pixel =
      rs.integer("spp", scene.settings.samples_per_pixel, 1, 1 << 20);
  scene.settings.max_depth = rs.integer("max_depth", scene.settings.max_depth, 1, 1024);
  scene.settings.noise_target =
      static_cast<float>(rs.number("noise_target", scene.settings.noise_target, 0.0, 1.0));
  scene.settings.min_samples = rs.integer("min_spp", scene.settings.min_samples, 1, 1 << 20);
  scene.settings.seed = static_cast<std::uint64_t>(rs.integer("seed", 1, 0, 2147483647));
  scene.settings.sample_sky = rs.boolean("sample_sky", scene.settings.sample_sky);
  rs.finish();

  Section out(subtable(root, "output", path), "output", path);
  for (const std::string& f : out.strings("files")) scene.outputs.emplace_back(f);
  read_exposure(out, subtable(root, "output", path), scene.display);
  const auto tone = out.string("tone");
  if (tone && *tone != "filmic" && *tone != "clamp") {
    throw Error(path.string() + ": 'output.tone' is '" + *tone + "'; use \"filmic\" or \"clamp\"");
  }
  scene.display.curve =
      (tone && *tone == "clamp") ? render::ToneCurve::Clamp : render::ToneCurve::Filmic;
  const std::string balance = out.string("white_balance").value_or("daylight");
  if (balance != "daylight" && balance != "none") {
    throw Error(path.string() + ": 'output.white_balance' is '" + balance +
                "'; use \"daylight\" (the sun 60 degrees up reads white) or \"none\" (sRGB's D65)");
  }
  scene.display.white_balance =
      balance == "daylight" ? render::kDaylightWhiteBalance : std::array<float, 3>{1, 1, 1};
  out.finish();
  return scene;
}

namespace {
// Reads a raster the scene places in metres; degrees are an error with the fix.
terrain::HeightField read_metric_raster(const fs::path& file) {
  terrain::HeightField grid = terrain::read_raster(file);
  require_metric_crs(grid, file);
  return grid;
}

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
  // Meridian convergence: the grid direction of true north at the centre.
  const auto centre = dem.geo().cell_center((dem.width() - 1) / 2.0, (dem.height() - 1) / 2.0);
  const auto north = terrain::from_lonlat(dem.geo().crs_wkt, lonlat[0], lonlat[1] + 1e-3);
  const double convergence =
      std::atan2(north[0] - centre[0], north[1] - centre[1]) * 180.0 / std::numbers::pi;
  scene.input.sun.azimuth_deg = std::fmod(sun.azimuth_deg + convergence + 720.0, 360.0);
  scene.input.sun.elevation_deg = sun.elevation_deg;
}

// Replaces the scene's objects by their snowy versions from drift snow fall:
// the same objects in the same order, raised by their snow, keeping their
// colours, with per-vertex snow coverage.
void place_snowy_objects(SceneFile& scene) {
  std::vector<terrain::PlacedMesh>& meshes = scene.input.meshes;
  const terrain::Mesh snowy = terrain::read_ply(scene.snow_objects);
  std::vector<terrain::Mesh> parts;
  try {
    parts = terrain::split_by_attribute(snowy, "object");
  } catch (const Error& e) {
    throw Error("'" + scene.snow_objects.string() + "': " + e.what() +
                " (write it with drift snow fall --mesh-out)");
  }
  if (parts.size() != meshes.size()) {
    throw Error("'" + scene.snow_objects.string() + "' holds " + std::to_string(parts.size()) +
                " objects but the scene has " + std::to_string(meshes.size()) +
                "; give the scene the objects file drift snow fall was given");
  }
  for (std::size_t o = 0; o < parts.size(); ++o) {
    const std::vector<float>* cover = parts[o].attribute("snow_coverage");
    meshes[o].position = parts[o].origin;
    meshes[o].snow_coverage = cover ? *cover : std::vector<float>{};
    meshes[o].mesh = std::move(parts[o]);
  }
}

// Turns the camera's lon/lat ends into CRS points at their height above the
// (exaggerated) ground, which must be inside the DEM.
void place_lonlat_camera(SceneFile& scene) {
  const terrain::HeightField& dem = scene.input.terrain;
  auto place = [&](const GeoPoint& p, const char* key) {
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
  };
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

void load_scene_terrain(SceneFile& scene) {
  render::TerrainSurface& surface = scene.input.surface;
  scene.input.terrain = read_metric_raster(scene.terrain_raster);
  if (scene.terrain_repeat > 1) {
    scene.input.terrain = terrain::repeat_periodic(scene.input.terrain, scene.terrain_repeat);
  }
  place_lonlat_camera(scene);
  if (scene.sun_time) place_sun(scene);
  if (!scene.snow_objects.empty()) place_snowy_objects(scene);
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
  if (!scene.snow_cover.empty()) surface.snow_cover = read_metric_raster(scene.snow_cover);
  if (!scene.snow_depth.empty()) surface.snow_depth = read_metric_raster(scene.snow_depth);
  if (!scene.ripples.empty() && surface.ripples) {
    terrain::HeightField tile = read_metric_raster(scene.ripples);
    const double native = tile.geo().cell_size_x();
    const double texel = scene.ripple_texel_metres.value_or(native);
    // A ripple field scaled to another cell size is scaled as a whole, heights
    // too, so its slopes (what shading sees) stay those simulated.
    if (native > 0.0 && texel != native) {
      for (float& v : tile.values()) v = static_cast<float>(v * (texel / native));
    }
    try {
      surface.ripples->slopes = render::SlopePyramid(tile, texel);
    } catch (const Error& e) {
      throw Error("ripple raster '" + scene.ripples.string() + "': " + e.what());
    }
  }
}

}  // namespace drift::pipeline
