// Scene files (TOML) for `drift render`: parsing with strict validation.
// Unknown keys, wrong types and out-of-range values are drift::Error naming the
// key, the file and the line. See docs/rendering.md for every key.
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/scene_variables.h"
#include "render/render_settings.h"
#include "render/solar_position.h"
#include "render/tonemap.h"

namespace drift::pipeline {

// A camera end given by longitude/latitude and a height above the ground,
// placed once the terrain is loaded.
struct GeoPoint {
  double lon = 0.0, lat = 0.0;  // degrees, WGS 84
  double above_ground = 0.0;    // metres
};

// One [[camera.keyframe]]: its time and camera ends (CRS points, or lon/lat
// placed on the DEM by load_scene_terrain) and field of view.
struct KeyframeSpec {
  double time = 0.0;
  std::optional<Eigen::Vector3d> from, to;
  std::optional<GeoPoint> from_lonlat, to_lonlat;
  double fov_deg = 40.0;
};

// A map render ([camera] projection = "map", or drift render --map): straight
// down over `box` (west, south, east, north in the DEM's CRS; none: the
// DEM's extent) at `cell` metres a pixel (0: the DEM's cell), placed by
// load_scene_terrain.
struct MapRequest {
  std::optional<std::array<double, 4>> box;
  double cell = 0.0;
};

struct SceneFile {
  std::filesystem::path terrain_raster;  // resolved against the scene file's folder
  std::filesystem::path albedo_map;      // likewise; empty when the scene has none
  // The masks of input.surface.layers, in order (read by load_scene_terrain).
  std::vector<std::filesystem::path> layer_masks;
  // [terrain] surround: coarser DEMs around the terrain (render/surround.h).
  std::vector<std::filesystem::path> surround_rasters;
  // The product files the stages' sections name, by "section.key" ("snow.cover",
  // "ripples.raster": pipeline/scene_products.h), resolved likewise; drift
  // render's flags override them.
  std::map<std::string, std::filesystem::path> product_files;
  // What puts a stage section's products into `input` once the terrain is
  // loaded, by section, in the order of the sections (load_scene_terrain).
  using Loader = std::function<void(SceneFile&)>;
  std::vector<std::pair<std::string, Loader>> product_loaders;
  double position_radius = 150.0;  // [terrain] position_radius: metres (render/land_form.h)
  int terrain_repeat = 1;          // [terrain] repeat: a tileable terrain laid out n x n (odd)
  // [camera] from_lonlat / to_lonlat: resolved into input.camera by
  // load_scene_terrain.
  std::optional<GeoPoint> camera_from_lonlat, camera_to_lonlat;
  // [sun] date/time/timezone: the sun over the DEM's centre, placed by
  // load_scene_terrain.
  std::optional<render::LocalTime> sun_time;
  // A camera path ([[camera.keyframe]], render/camera.h: camera_at) and the
  // time to render it at (drift render --time; default its first key's),
  // resolved into input.camera by load_scene_terrain.
  std::vector<KeyframeSpec> keyframes;
  std::optional<double> time;
  // A map render: resolved by load_scene_terrain into input.camera, the
  // size in `settings` and `map_geotransform` (GDAL's, of the frame).
  std::optional<MapRequest> map;
  std::array<double, 6> map_geotransform{0, 1, 0, 0, 0, -1};
  render::SceneInput input;  // terrain not loaded yet (see load_scene_terrain)
  render::RenderSettings settings;
  std::vector<std::filesystem::path> outputs;  // resolved against the current directory
  render::DisplayTransform display;

  // The product file `key` names ("snow.cover"), or an empty path.
  std::filesystem::path product_file(const std::string& key) const;
  // Whether stage section `name` makes products (has a loader).
  bool loads(const std::string& name) const;
};

// The scene file's sections, the stages' (pipeline/scene_products.h) among
// the renderer's own, in the order they are read and listed in errors.
std::vector<std::string> scene_sections();

// Parses and validates; meshes are loaded, the terrain raster is not.
// `variables` replace the defaults of the file's [variables] table
// (pipeline/scene_variables.h).
SceneFile read_scene_file(const std::filesystem::path& path, const SceneVariables& variables = {});

// Every file the scene reads (rasters, masks, product files), for refusing
// them as outputs.
std::vector<std::filesystem::path> scene_inputs(const SceneFile& scene);

// Replaces the scene's camera path with the [[camera.keyframe]] entries of
// the TOML file `path` (drift render --camera-path): one path for many
// scenes, or many paths for one.
void read_camera_path(const std::filesystem::path& path, SceneFile& scene);

// Reads the scene's terrain raster and layer rasters; a geographic (degree)
// raster is an error telling the user to run `drift import` first.
void load_scene_terrain(SceneFile& scene);

}  // namespace drift::pipeline
