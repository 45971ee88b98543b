// A scene as read from its file (pipeline/scene_file.h): the renderer's input
// with the files it names and what loads them once the terrain is loaded.
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

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
  // The files [[objects]] and [terrain] objects name (the objects file and its
  // meshes): inputs too, so no output may replace them (issue 34).
  std::vector<std::filesystem::path> object_files;
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
  // > 0: load_scene_terrain reads the DEM resampled to at most this many
  // cells a side (an out-of-core render reads the full one in pages).
  int coarse_terrain_side = 0;
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
  // Whether anything before the scene reads the DEM's heights or its grid
  // (a repeat, a camera or sun placed on it, a map's cells, topographic
  // position, snow depth laid on it): if not, the scene may read the DEM
  // itself (drift render --height-bits 16 quantises it strip by strip) and
  // load_scene_terrain a coarse stand-in (coarse_terrain_side).
  bool needs_dem_before_scene() const;
};

}  // namespace drift::pipeline
