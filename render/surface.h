// What covers the terrain: materials and the products that place them, by
// their declared form (terrain/products.h), never by the stage that made
// them: material masks (MaterialLayer, such as snow cover, with a thickness
// such as snow depth), normal-detail tiles (NormalDetail) and the materials
// objects' per-vertex attributes place (ObjectLayer). Every raster is sampled by
// CRS coordinates, so it need not share the DEM's grid, only its CRS.
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <vector>

#include "render/coverage.h"
#include "render/material.h"
#include "render/normal_map.h"
#include "terrain/grid.h"

namespace drift::render {

// A material layer's thickness (a height change it also is, e.g. snow depth):
// thin, it lets what lies beneath show through. Where the layer lies it is
// metres / weight deep (the weight is its share of the ground), at least
// kFlakeDepth where it shows as flakes, and reflects layer_albedo(its albedo,
// the albedo beneath, scattering x that depth) (render/material.h).
// Kubelka-Munk scattering coefficient of fresh snow, per metre: about 0.1 mm
// grains at 300 kg/m^3 (reduced scattering ~500/m, Wiscombe & Warren 1980);
// 1 cm of it over black rock reflects 0.79 where deep snow reflects 0.90.
inline constexpr float kFreshSnowScattering = 400.0f;

struct LayerThickness {
  // Beyond the raster and at nodata the layer is opaque (as deep as it needs
  // to be: the storm's snow around a cropped snowfall); below zero: none.
  terrain::HeightField metres;
  // Kubelka-Munk scattering coefficient S, per metre.
  float scattering = kFreshSnowScattering;
};

// A material placed by a raster in the DEM's CRS (a material mask,
// terrain/products.h): the mask's value in [0, 1] (clamped; nodata counts as
// `outside`, as does everything beyond the raster) times `opacity` blends the
// fields `material` sets over what lies beneath.
struct MaterialLayer {
  std::string name = "layer";  // its coverage channel (render/coverage.h)
  MaterialOverride material;
  terrain::HeightField mask;
  float opacity = 1.0f;
  // The mask's value where the raster does not reach (beyond a cropped
  // snowfall, on the ground around the DEM: render/surround.h).
  float outside = 0.0f;
  // Snow placed by a mask: a weight below 1 shows as flakes covering that
  // share of the ground (render/snow_flakes.h), not as a pale film. The scene
  // file sets it for layers of the `snow` preset.
  bool flakes = false;
  std::optional<LayerThickness> thickness;  // none: opaque however thin
  // Whether normal details (ripples) fade under it by its weight: snow buries
  // them, a change of colour does not.
  bool buries_details = false;
};

// A material placed on objects by a per-vertex attribute of their meshes
// (an attributed mesh, terrain/products.h): the attribute's value in [0, 1],
// interpolated over each triangle, blends `material` over the object's
// colour, e.g. snow by terrain::products::kSnowCoverage.
struct ObjectLayer {
  std::string attribute;  // the meshes' per-vertex attribute
  std::string name;       // its coverage channel (render/coverage.h)
  Material material;
  bool flakes = true;  // a value below 1 shows as flakes (render/snow_flakes.h)
};

// A normal-detail tile: a periodic height tile bump-mapped on the ground,
// e.g. wind ripples (paper 002, section 5). It fades under snow and on steep
// slopes (ripples do not survive on slip faces).
struct NormalDetail {
  SlopePyramid slopes;           // of the periodic height tile
  double rotation_deg = 0.0;     // tile turned clockwise on the ground (e.g. to the wind)
  float strength = 1.0f;         // scales the tile's slopes
  float fade_start_deg = 24.0f;  // the detail fades out between these terrain
  float fade_end_deg = 31.0f;    // slopes
};

// The ground's material, bottom to top: `ground` (its albedo from
// `albedo_map` where that covers the point), then `rules` by altitude and
// slope, then `layers` by their masks (a stage's material masks, such as snow
// cover, last), each over what lies beneath in order; then the normal
// details, in order. Objects take `object_layers` by their meshes'
// attributes.
struct TerrainSurface {
  Material ground;
  std::string ground_name = "ground";  // its coverage channel (render/coverage.h)
  std::vector<MaterialRule> rules;
  std::vector<MaterialLayer> layers;
  std::vector<NormalDetail> normal_details;
  // The ground's albedo draped from an image in the DEM's CRS (an orthophoto
  // or a land-cover colour map): linear R, G, B in [0, 1]; outside it the
  // ground material's colour.
  std::optional<std::array<terrain::HeightField, 3>> albedo_map;
  // Topographic position index (render/land_form.h) for rules that use
  // `position`, in the DEM's CRS; made from the DEM when the scene is loaded.
  std::optional<terrain::HeightField> position;
  std::vector<ObjectLayer> object_layers;
  // The DEM's cell (m; 0: not known): ground detail below it only
  // (render/ground_detail.h), set by the scene from its terrain.
  double cell = 0.0;
};

// Reads a draped albedo image (GeoTIFF or any GDAL raster): 3 bands (or 1,
// grey); 8/16-bit values are sRGB-encoded and decoded to linear, float values
// are taken as linear albedo.
std::array<terrain::HeightField, 3> read_albedo_map(const std::filesystem::path& path);

// The material at a terrain point, after layers.
struct SurfacePoint {
  Material material;
  Eigen::Vector3f normal{0, 0, 1};  // unit shading normal (bumped)
  // The share of the ground under layers that bury details (snow), for
  // the normal details.
  float buried = 0.0f;
  Coverage coverage{};  // shares by CoverageChannels (if asked for)
};

// Bilinear sample of `raster` at CRS coordinates (x, y); cells outside or
// nodata count as `outside`.
float sample_raster(const terrain::HeightField& raster, double x, double y, float outside);

// `dem` with the height change `metres` (sampled at each cell centre;
// outside, nodata and values below zero count as none) added to its valid
// cells.
terrain::HeightField add_height_change(const terrain::HeightField& dem,
                                       const terrain::HeightField& metres);

// Where a terrain point lies, for material rules: its altitude in metres
// (without vertical exaggeration) and the slope of the unbumped terrain in
// degrees (likewise).
struct Relief {
  float altitude = 0.0f;
  float slope_deg = 0.0f;
  // The point's rendered height (CRS metres, exaggerated): with (x, y) it
  // places world-space patterns (render/snow_flakes.h).
  double z = 0.0;
  // The ray's direction (unit; zero: unknown): at grazing angles the
  // footprint stretches along it (render/snow_flakes.h).
  Eigen::Vector3f ray{0, 0, 0};
};

// Evaluates the layers at CRS point (x, y) with the smooth terrain normal
// `normal` (unit, z up) and a ray footprint `footprint` metres wide; with
// `channels` (coverage_channels(surface)) also the coverage shares.
SurfacePoint shade_terrain(const TerrainSurface& surface, double x, double y,
                           const Eigen::Vector3f& normal, double footprint,
                           const Relief& relief = {}, const CoverageChannels* channels = nullptr);

// The coverage channels of a surface's stack (render/coverage.h). Throws
// drift::Error if the stack has more than kMaxCoverage distinct names.
CoverageChannels coverage_channels(const TerrainSurface& surface);

}  // namespace drift::render
