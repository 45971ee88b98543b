// drift render SCENE.toml: path-trace a scene file into EXR and/or PNG.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <regex>

#include "pipeline/cli.h"
#include "pipeline/progress_bar.h"
#include "pipeline/scene_file.h"
#include "pipeline/scene_products.h"
#include "pipeline/scene_variables.h"
#include "render/camera_setup.h"
#include "render/frame_sidecar.h"
#include "render/image_io.h"
#include "render/map_output.h"
#include "render/paged_terrain.h"
#include "render/renderer.h"
#include "render/tiles.h"
#include "terrain/atomic_file.h"
#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/output_set.h"
#include "terrain/raster_blocks.h"

namespace drift::pipeline {

namespace {

// Cells a side of the coarse stand-in for the relief that what runs before
// the scene (placing the camera, the sun) sees when the scene itself reads
// the DEM in pages or strips, not whole.
constexpr int kCoarseTerrainSide = 1024;

struct RenderOptions {
  std::string scene;
  std::vector<std::string> variables;  // --set NAME=VALUE
  int spp = 0;
  double noise_target = -1.0;  // < 0: the scene's
  std::string size;
  std::vector<std::string> outputs;
  std::string terrain;
  // The stages' product-file flags (--snow-cover, --ripples, ...;
  // pipeline/scene_products.h), in the table's order, each with its value.
  struct ProductFlag {
    const StageSection* section;
    const ProductFileKey* file;
    std::string value;
  };
  std::vector<ProductFlag> product_flags;
  unsigned long long seed = 0;
  std::string tile;
  std::string sun_time;
  double exposure_ev = 0.0;
  double compensation_ev = 0.0;
  bool map = false;
  bool sidecar = false;
  double time = 0.0;
  std::string camera_path;
  std::string from, to;  // --from/--to X,Y,Z in the CRS
  std::string map_box;
  double cell = 0.0;
  std::string memory_budget;     // --memory-budget BYTES: the terrain out of core
  bool full_resolution = false;  // --full-resolution: no level of detail out of core
  int height_bits = 32;          // --height-bits 16: heights quantised over each block in core
};

// X,Y,Z (CRS metres) of --from or --to.
Eigen::Vector3d parse_point(const std::string& flag, const std::string& text) {
  std::smatch m;
  const std::string number = R"(\s*([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*)";
  if (!std::regex_match(text, m, std::regex(number + "," + number + "," + number)))
    usage_error(flag + " '" + text + "' must be X,Y,Z in the DEM's CRS (metres), e.g. " +
                "741000,4029000,3200");
  return {std::stod(m[1]), std::stod(m[2]), std::stod(m[3])};
}

// --from and --to: where the camera stands and looks, over [camera]'s.
void apply_camera_flags(const RenderOptions& o, SceneFile& scene) {
  if (o.from.empty() && o.to.empty()) return;
  if (o.from.empty() || o.to.empty()) usage_error("--from and --to go together");
  render::Camera camera = scene.input.camera.value_or(render::Camera{});
  camera.from = parse_point("--from", o.from);
  camera.to = parse_point("--to", o.to);
  scene.input.camera = camera;
  scene.camera_from_lonlat.reset();
  scene.camera_to_lonlat.reset();
}

// --sidecar: NAME.json beside the first image output (its EXR if any).
void add_sidecar(const RenderOptions& o, SceneFile& scene) {
  if (!o.sidecar) return;
  std::filesystem::path image;
  for (const auto& f : scene.outputs)
    if (image.empty() || f.extension() == ".exr") image = f;
  if (image.empty()) return;  // check_outputs says there is nothing to write
  std::filesystem::path json = image;
  json.replace_extension(".json");
  if (std::find(scene.outputs.begin(), scene.outputs.end(), json) == scene.outputs.end())
    scene.outputs.push_back(json);
}

// --map, --map-box W,S,E,N and --cell M: a map render (either of the last
// two implies --map) over the scene's [camera].
void apply_map_flags(const RenderOptions& o, SceneFile& scene) {
  if (!o.map && o.map_box.empty() && o.cell <= 0.0) return;
  MapRequest request = scene.map.value_or(MapRequest{});
  if (!o.map_box.empty()) {
    std::smatch m;
    const std::string number = R"(\s*([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*)";
    if (!std::regex_match(o.map_box, m,
                          std::regex(number + "," + number + "," + number + "," + number))) {
      usage_error(
          "--map-box '" + o.map_box +
          "' must be WEST,SOUTH,EAST,NORTH in the DEM's CRS, e.g. 741000,4025000,745000,4029000");
    }
    const std::array<double, 4> box = {std::stod(m[1]), std::stod(m[2]), std::stod(m[3]),
                                       std::stod(m[4])};
    if (!(box[2] > box[0]) || !(box[3] > box[1]))
      usage_error("--map-box '" + o.map_box + "' must have EAST > WEST and NORTH > SOUTH");
    request.box = box;
  }
  if (o.cell > 0.0) request.cell = o.cell;
  scene.map = request;
}

// --sun-time "YYYY-MM-DD HH:MM[:SS] [+HH:MM]" (the offset as in [sun]
// timezone, default UTC) -> the scene's date and time.
render::LocalTime parse_sun_time(const std::string& text) {
  std::smatch m;
  if (!std::regex_match(text, m, std::regex(R"((\S+)\s+(\S+)(?:\s+(\S+))?)"))) {
    usage_error(
        "--sun-time '" + text +
        "' must be \"YYYY-MM-DD HH:MM[:SS] [UTC offset]\", e.g. \"2026-10-15 17:05 +09:00\"");
  }
  try {
    return render::parse_local_time(m[1], m[2], m[3].matched ? m[3].str() : "UTC");
  } catch (const Error& e) {
    usage_error(std::string("--sun-time: ") + e.what());
  }
}

// Says which exposure the PNGs got (a tile is metered when merged).
void print_exposure(const render::Image& image, const render::DisplayTransform& display,
                    bool whole_frame) {
  if (!display.auto_exposure || !whole_frame) return;
  const render::DisplayTransform fixed = render::resolve_exposure(image, display);
  std::printf("exposure: metered %+.2f EV (--exposure EV fixes it)\n", fixed.exposure_ev);
}

// --size WIDTHxHEIGHT into the settings.
void apply_size(const std::string& size, render::RenderSettings& settings) {
  std::smatch m;
  if (!std::regex_match(size, m, std::regex(R"((\d+)x(\d+))"))) {
    usage_error("--size '" + size + "' must be WIDTHxHEIGHT, e.g. 1280x720");
  }
  // Well formed but too large ("100000x100000") says so, not "must be WIDTHxHEIGHT".
  constexpr int kMax = render::RenderSettings::kMaxSide;
  const auto side = [&](const std::string& digits) {
    const int value = digits.size() > 6 ? kMax + 1 : std::stoi(digits);
    if (value < 1 || value > kMax) {
      usage_error("--size '" + size + "': each side must be 1.." + std::to_string(kMax));
    }
    return value;
  };
  settings.width = side(m[1]);
  settings.height = side(m[2]);
}

// The stages' product-file flags over their sections' keys; a section that
// makes no products without its keys (as [ripples]) must be there.
void apply_product_flags(const RenderOptions& o, SceneFile& scene) {
  for (const RenderOptions::ProductFlag& f : o.product_flags) {
    if (f.value.empty()) continue;
    if (!scene.loads(f.section->name)) {
      throw Error(std::string(f.file->flag) + " needs a [" + f.section->name + "] section in '" +
                  o.scene + "'; see docs/rendering.md");
    }
    scene.product_files[product_key(*f.section, *f.file)] = f.value;
  }
}

// The command line's overrides of the scene file.
void apply_overrides(const RenderOptions& o, const CLI::App& sub, SceneFile& scene) {
  if (o.spp > 0) scene.settings.samples_per_pixel = o.spp;
  if (o.noise_target >= 0.0) scene.settings.noise_target = static_cast<float>(o.noise_target);
  if (!o.size.empty()) apply_size(o.size, scene.settings);
  if (sub.count("--seed")) scene.settings.seed = o.seed;
  // Placed over the DEM when the terrain is loaded, replacing [sun]'s direction.
  if (!o.sun_time.empty()) scene.sun_time = parse_sun_time(o.sun_time);
  if (sub.count("--exposure-compensation")) {  // on top of the meter
    scene.display.exposure_ev = o.compensation_ev;
    scene.display.auto_exposure = true;
  }
  if (sub.count("--exposure")) {  // a fixed exposure instead of the meter
    scene.display.exposure_ev = o.exposure_ev;
    scene.display.auto_exposure = false;
  }
  if (!o.terrain.empty()) scene.terrain_raster = o.terrain;
  apply_product_flags(o, scene);
  if (!o.camera_path.empty()) read_camera_path(o.camera_path, scene);
  if (sub.count("--time")) {
    if (scene.keyframes.empty())
      usage_error("--time needs a camera path: [[camera.keyframe]] in '" + o.scene +
                  "' or --camera-path FILE");
    scene.time = o.time;
  }
  apply_map_flags(o, scene);
  apply_camera_flags(o, scene);
  if (!scene.keyframes.empty() && (scene.map || !o.from.empty()))
    usage_error("a camera path and --map or --from/--to: give one camera");
  if (scene.map && !o.from.empty())
    usage_error("--from/--to and a map render: a map looks straight down over its box");
  if (scene.map && !o.size.empty())
    usage_error("--size and a map render: a map's size is its box over its --cell");
  if (!o.outputs.empty()) {
    scene.outputs.clear();
    for (const auto& f : o.outputs) scene.outputs.emplace_back(f);
  }
  add_sidecar(o, scene);
}

// Outputs are PNG or EXR, a tile (--tile i/n) only EXR.
void check_outputs(const RenderOptions& o, SceneFile& scene) {
  if (scene.outputs.empty()) {
    throw Error("nothing to write: give -o NAME.png|NAME.exr or [output] files in '" + o.scene +
                "'");
  }
  for (const auto& f : scene.outputs) {
    std::string ext = f.extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (scene.map && render::is_geotiff_path(f)) continue;  // a GeoTIFF of the map
    if (ext == ".json") continue;                           // the frame's ground truth
    if (ext != ".png" && ext != ".exr") {
      throw Error("cannot write '" + f.string() + "': use a .png, .exr or .json file name" +
                  (scene.map ? ", or .tif (a GeoTIFF of the map)" : ""));
    }
  }
  if (o.tile.empty()) return;
  render::TileSpec tile;
  try {
    tile = render::parse_tile_spec(o.tile);
  } catch (const Error& e) {
    usage_error(std::string("--") + e.what());
  }
  const render::TileRect rect =
      render::tile_rect(scene.settings.width, scene.settings.height, tile);
  scene.settings.row_begin = rect.y.begin;
  scene.settings.row_end = rect.y.end;
  scene.settings.col_begin = rect.x.begin;
  scene.settings.col_end = rect.x.end;
  for (const auto& f : scene.outputs) {
    if (f.extension() != ".exr" && f.extension() != ".json") {
      throw Error("a tile is written as EXR (it keeps its place in the frame); '" + f.string() +
                  "' is not: give -o TILE.exr and join the tiles with drift merge");
    }
  }
}

// Which scene and settings an image comes from, recorded in it so that drift
// merge refuses tiles of different renders: FNV-1a of the scene file's bytes and
// of every option that changes pixels (not --tile, not the outputs).
std::string scene_identity(const RenderOptions& o, const SceneFile& scene) {
  std::ifstream in(o.scene, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  std::vector<std::string> parts = {o.size,
                                    o.terrain,
                                    o.from,
                                    o.to,
                                    o.camera_path,
                                    std::to_string(o.time),
                                    o.map_box,
                                    std::to_string(o.map),
                                    std::to_string(o.cell)};
  for (const RenderOptions::ProductFlag& f : o.product_flags) parts.push_back(f.value);
  parts.insert(
      parts.end(),
      {o.sun_time, std::to_string(scene.settings.samples_per_pixel),
       std::to_string(scene.settings.noise_target), std::to_string(scene.settings.seed),
       std::to_string(scene.display.exposure_ev), std::to_string(scene.display.auto_exposure)});
  for (const std::string& part : parts) text.append("\n").append(part);
  std::uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : text) hash = (hash ^ c) * 1099511628211ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return hex;
}

// Every output; a map's with its georeference (render/map_output.h).
void write_outputs(const SceneFile& scene, const render::Image& image,
                   const render::TerrainScene& embree_scene, const render::Camera& camera) {
  render::MapGeoreference geo;
  geo.geotransform = scene.map_geotransform;
  geo.crs_wkt = scene.input.terrain.geo().crs_wkt;
  for (const auto& f : scene.outputs) {
    if (f.extension() == ".json") {
      const std::string json =
          render::frame_sidecar_json(embree_scene, scene.input, camera, scene.settings);
      AtomicFile file(f);
      write_all_bytes(file.temp_path(), json.data(), json.size(), f);
      file.commit();
      continue;
    }
    if (scene.map && render::is_geotiff_path(f)) {
      render::write_map_geotiff(image, scene.display, geo, f);
      continue;
    }
    render::write_image(image, f, scene.display);
    if (scene.map && f.extension() == ".png") render::write_map_png_sidecars(f, geo);
  }
}

void print_summary(const SceneFile& scene, const render::Image& image,
                   const render::RenderStats& stats, double seconds) {
  if (scene.settings.noise_target > 0.0f) {
    const double mean_spp =
        static_cast<double>(stats.camera_rays) / (static_cast<double>(image.width) * image.height);
    std::printf("rendered %dx%d at %.1f spp on average (noise target %g, at most %d) in %.1f s -> ",
                image.width, image.height, mean_spp, scene.settings.noise_target,
                scene.settings.samples_per_pixel, seconds);
  } else {
    std::printf("rendered %dx%d at %d spp in %.1f s -> ", image.width, image.height,
                scene.settings.samples_per_pixel, seconds);
  }
  for (const auto& f : scene.outputs) std::printf("%s ", f.c_str());
  std::printf("\n");
}

// The out-of-core terrain's page cache over the render (render/block_cache.h).
void print_cache(const render::PagedTerrain& paged, double setup_seconds) {
  const render::BlockCacheStats c = paged.cache_stats();
  std::printf(
      "terrain cache: %llu hits, %llu misses, %s read in pages (%s in the opening scan), "
      "peak resident %s of a %s budget (%s of it held outside the pages: bounds, coarse "
      "levels, BVH); scene set-up %.1f s\n",
      static_cast<unsigned long long>(c.hits), static_cast<unsigned long long>(c.misses),
      human_bytes(c.bytes_read).c_str(), human_bytes(paged.scan_bytes()).c_str(),
      human_bytes(c.peak_resident + paged.held_bytes()).c_str(),
      human_bytes(paged.budget() + paged.held_bytes()).c_str(),
      human_bytes(paged.held_bytes()).c_str(), setup_seconds);
}

// --set NAME=VALUE, each a usage error unless NAME can name a variable.
SceneVariables scene_variables(const std::vector<std::string>& settings) {
  SceneVariables variables;
  for (const std::string& setting : settings) {
    const std::size_t equals = setting.find('=');
    const std::string name = setting.substr(0, equals);
    if (equals == std::string::npos || !is_variable_name(name))
      usage_error("--set '" + setting +
                  "' must be NAME=VALUE with NAME of letters, digits and '_' (e.g. OUT=out)");
    variables[name] = setting.substr(equals + 1);
  }
  return variables;
}

void run_render(const RenderOptions& o, const CLI::App& sub) {
  SceneFile scene = read_scene_file(o.scene, scene_variables(o.variables));
  apply_overrides(o, sub, scene);
  check_outputs(o, scene);
  std::vector<std::filesystem::path> inputs = scene_inputs(scene);
  inputs.emplace_back(o.scene);
  std::vector<std::filesystem::path> written = scene.outputs;
  if (scene.map) {  // a map PNG's world file and .aux.xml are written with it
    for (const auto& f : scene.outputs)
      if (f.extension() == ".png")
        for (const auto& side : render::map_png_sidecars(f)) written.push_back(side);
  }
  std::optional<std::uint64_t> budget;
  if (!o.memory_budget.empty()) {
    budget = parse_byte_size(o.memory_budget);
    if (!budget)
      usage_error("--memory-budget '" + o.memory_budget +
                  "' is not a size; give bytes with an optional K, M, G or T (e.g. 4G, 512M)");
    // Out of core: what needs the relief before the scene (placing the
    // camera, the sun) sees a coarse stand-in; the scene reads the full
    // raster in pages.
    scene.coarse_terrain_side = kCoarseTerrainSide;
    if (o.height_bits == 16)
      usage_error(
          "--height-bits 16 quantises the heights held in core; with --memory-budget "
          "the pages hold float heights: give one of the two");
  }
  // --height-bits 16 in core: the scene reads the DEM strip by strip and
  // quantises it as it reads (the floats never all exist, issue 36) unless
  // something before the scene needs the whole DEM.
  const bool streamed = !budget && o.height_bits == 16 && !scene.needs_dem_before_scene();
  if (streamed) scene.coarse_terrain_side = kCoarseTerrainSide;
  OutputSet outputs(written, inputs);
  load_scene_terrain(scene);
  const auto start = std::chrono::steady_clock::now();
  // The DEM's cells move into the scene (held once), or stay on disk and are
  // read in pages (--memory-budget); its georeference stays with the input
  // for the outputs that name it (EXR crsWKT, sidecar, map).
  std::unique_ptr<render::PagedTerrain> paged;
  std::unique_ptr<render::TerrainScene> scene_holder;
  if (budget) {
    paged = std::make_unique<render::PagedTerrain>(
        scene.terrain_raster, *budget, static_cast<float>(scene.input.vertical_exaggeration));
    scene.input.terrain = terrain::HeightField();
    scene.input.terrain.geo() = paged->geo();
    scene_holder = std::make_unique<render::TerrainScene>(scene.input, *paged);
  } else if (streamed) {
    scene_holder = std::make_unique<render::TerrainScene>(scene.input, scene.terrain_raster);
    scene.input.terrain = terrain::HeightField();
    scene.input.terrain.geo() = terrain::RasterBlockReader(scene.terrain_raster).geo();
  } else {
    const terrain::GeoReference dem_geo = scene.input.terrain.geo();
    scene_holder = std::make_unique<render::TerrainScene>(
        scene.input, std::move(scene.input.terrain),
        o.height_bits == 16 ? render::TerrainGeometry::HeightField16
                            : render::TerrainGeometry::Auto);
    scene.input.terrain.geo() = dem_geo;
  }
  const render::TerrainScene& embree_scene = *scene_holder;
  // The terrain (in memory, or its pages, cache and tree out of core) stays
  // while the image is made and written: the image's check adds the largest
  // check so far, the terrain's (they were separate, so a large image with a
  // large --memory-budget counted only the larger; docs/outputs.md).
  const HeldMemory terrain_held(memory_estimate_bytes(), "the terrain");
  const double setup_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const render::Camera camera =
      scene.input.camera ? *scene.input.camera : render::default_camera(embree_scene);
  if (paged && !o.full_resolution) {
    // Out of core, distant ground at coarser levels by the pixel's footprint
    // (docs/rendering.md, "Level of detail by footprint").
    const render::CameraRays rays =
        render::make_camera_rays(embree_scene, camera, scene.settings.width, scene.settings.height);
    scene_holder->set_lod({rays.eye, rays.footprint_spread()});
  }
  render::RenderStats stats;
  render::Image image = render::render_image(embree_scene, scene.input, camera, scene.settings,
                                             terminal_progress("render"), &stats);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The display settings ride along so that `drift merge` can write the PNG.
  image.attributes = {
      {"exposure",
       scene.display.auto_exposure ? "auto" : std::to_string(scene.display.exposure_ev)},
      {"exposure_compensation",
       std::to_string(scene.display.auto_exposure ? scene.display.exposure_ev : 0.0)},
      {"tone", scene.display.curve == render::ToneCurve::Clamp ? "clamp" : "filmic"},
      {"white_balance",
       scene.display.white_balance == render::kDaylightWhiteBalance ? "daylight" : "none"},
      {"scene", scene_identity(o, scene)}};
  write_outputs(scene, image, embree_scene, camera);
  outputs.commit();
  print_summary(scene, image, stats, seconds);
  if (paged) print_cache(*paged, setup_seconds);
  print_exposure(image, scene.display, o.tile.empty());
}

// One flag per product file of the stages' sections, e.g. --snow-cover
// "snow cover raster (overrides [snow] cover)".
void add_product_flags(CLI::App& sub, RenderOptions& o) {
  for (const StageSection& section : stage_sections())
    for (const ProductFileKey& file : section.files)
      o.product_flags.push_back({&section, &file, ""});
  // Bound once the list is complete: the values must not move.
  for (RenderOptions::ProductFlag& f : o.product_flags) {
    sub.add_option(
        f.file->flag, f.value,
        std::string(f.file->what) + " (overrides [" + f.section->name + "] " + f.file->key + ")");
  }
}

}  // namespace

// The flags, as data: pipeline/cmd_render_flags.toml.
#include "pipeline/cmd_render_flags.inc"

DRIFT_COMMAND(70, "render", "path-trace a scene file (TOML) to EXR and/or PNG", render_flags,
              run_render);

}  // namespace drift::pipeline
