// Everything a render needs, as plain data. The scene-file parser
// (pipeline/scene_file) fills it; tests build it directly.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "render/camera.h"
#include "render/clouds.h"
#include "render/surface.h"
#include "render/surround.h"
#include "terrain/grid.h"
#include "terrain/mesh.h"
#include "terrain/products.h"

namespace drift::render {

struct Sun {
  double azimuth_deg = 135.0;          // clockwise from north, [0, 360)
  double elevation_deg = 35.0;         // above the horizon, [-90, 90]
  double angular_diameter_deg = 0.53;  // the real sun; (0, 20]
  double irradiance = 3.0;             // on a surface facing the sun, render units (W/m^2 scaled)
  Eigen::Vector3f color{1.0f, 0.95f, 0.88f};  // linear RGB tint
};

// The sky. Physical (the default): an Earth atmosphere (render/atmosphere.h)
// lights the scene, colours the sun and fills the air between the camera and
// the ground (aerial perspective); `haze` scales its aerosols. Simple: an
// analytic gradient from `horizon` to `zenith` with the sine of the elevation
// (below the horizon `horizon` * ground_factor) and no air. `constant`: the
// same radiance `intensity` everywhere (white-furnace tests).
enum class SkyModel { Physical, Simple };

struct Sky {
  SkyModel model = SkyModel::Physical;
  float haze = 1.0f;  // aerosol density relative to Bruneton 2017's (visibility ~ 1/haze)
  Eigen::Vector3f zenith{0.25f, 0.42f, 0.80f};
  Eigen::Vector3f horizon{0.70f, 0.78f, 0.90f};
  float intensity = 1.0f;      // multiplies both
  float ground_factor = 1.0f;  // below the horizon: horizon x this (distant haze)
  bool constant = false;       // constant radiance `intensity` everywhere (white furnace)
  // Physical sky only: the terrain's shadow on the air seen from the camera
  // (render/light_shafts.h), tested at `shaft_steps` points per camera ray.
  bool light_shafts = false;
  int shaft_steps = 16;
};

struct RenderSettings {
  // The ranges the scene file and the command line both hold the settings to.
  static constexpr int kMaxSide = 16384;               // width and height, pixels
  static constexpr int kMaxSamplesPerPixel = 1 << 20;  // samples_per_pixel, min_samples

  int width = 960;
  int height = 540;
  int samples_per_pixel = 64;  // the most a pixel takes
  // Adaptive sampling: a pixel stops once the estimated relative standard
  // error of its mean luminance is below noise_target (0: off, every pixel
  // takes samples_per_pixel), after at least min_samples.
  float noise_target = 0.0f;
  int min_samples = 16;
  int max_depth = 4;  // path vertices after the camera; >= 1
  std::uint64_t seed = 1;
  // Next-event estimation of the sky (importance-sampled, combined with the
  // BSDF's bounces by multiple importance sampling); false: the sky is only
  // found by bounces (brute force, for tests and comparisons).
  bool sample_sky = true;
  // Render only rows [row_begin, row_end) of the frame (one tile of it); the
  // pixels are the same bits as in a whole-frame render. row_end 0: to the end.
  int row_begin = 0;
  int row_end = 0;
  // Likewise columns [col_begin, col_end) (a block of a --tile i/CxR grid).
  int col_begin = 0;
  int col_end = 0;
};

struct SceneInput {
  terrain::HeightField terrain;  // metric CRS (or local), heights in metres
  double vertical_exaggeration = 1.0;
  // Height changes laid on the ground (terrain/products.h): the surface
  // traced is the terrain raised by each, in order.
  std::vector<terrain::products::HeightChange> height_changes;
  TerrainSurface surface;    // materials and the layers that place them
  SurroundOptions surround;  // the ground beyond the DEM's edge (render/surround.h)
  // Objects, each an attributed mesh (terrain/products.h) placed in the scene:
  // a kSnowCoverage attribute puts the snow material on it.
  std::vector<terrain::PlacedMesh> meshes;
  // Their names for the object mattes (render/mattes.h), by index; missing
  // or empty: "object<N>".
  std::vector<std::string> object_names;
  Sun sun;
  Sky sky;
  CloudOptions clouds;           // a cloud layer (render/clouds.h); physical sky only
  std::optional<Camera> camera;  // none: the default view of the terrain
};

}  // namespace drift::render
