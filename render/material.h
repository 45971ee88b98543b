// Ground materials: a rough diffuse base (Oren-Nayar) with an optional wet
// coat, named presets with typical measured albedos, and the rules that choose
// materials by altitude and slope. Rasters (masks) that place materials are in
// render/surface.h; the reflectance model itself is render/bsdf.h.
//
// | field     | meaning                                             | range    |
// |-----------|-----------------------------------------------------|----------|
// | albedo    | linear RGB diffuse albedo of the dry material       | [0, 1]^3 |
// | roughness | Oren-Nayar facet slope deviation sigma, radians     | [0, 1.5] |
// | wetness   | share of a water film: darker base, glossy coat     | [0, 1]   |
// | forward_scattering | share of the snowpack's single-scattering lobe | [0, 1]   |
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace drift::render {

// Oren-Nayar sigma beyond which the model is not meant to be used (radians).
constexpr float kMaxRoughness = 1.5f;

// Relief and colour below the DEM's cell (render/ground_detail.h): procedural,
// deterministic, filtered by the ray's footprint.
struct GroundDetail {
  float variation = 0.0f;  // relative standard deviation of the albedo (0.2: +-20 %)
  float bump = 0.0f;       // rms slope of the sub-cell relief (tan of the facets' tilt)
  float scale = 4.0f;      // metres: wavelength of the relief's largest features
  // Share of the relief's slope variance carried by jointed blocks (rock:
  // facets with crisp edges, dark joints, ledges on steep faces) instead of
  // smooth noise; 0 for soft ground (render/ground_detail.h).
  float fracture = 0.0f;
};

struct Material {
  Eigen::Vector3f albedo{0.28f, 0.26f, 0.23f};
  float roughness = 0.0f;  // sigma of the facet slopes, radians; 0 is Lambert
  float wetness = 0.0f;    // 0 dry, 1 a continuous water film (render/bsdf.h)
  // Share of the reflection by a forward-scattering granular medium (snow:
  // single scattering by ice grains, render/bsdf.h); 0 plain rough diffuse.
  float forward_scattering = 0.0f;
  GroundDetail detail{};  // none by default (objects, tests)
};

// Linear blend of every field: (1 - t) a + t b.
Material mix(const Material& a, const Material& b, float t);

// The named presets (land classes: rock, dark_rock, scree, meadow, dwarf_pine,
// forest; and sand, mud, soil, grass, snow), or nullopt for an unknown
// name. Values and their sources are in material.cpp.
std::optional<Material> material_preset(std::string_view name);
// The presets' names, comma-separated, for error messages.
std::string material_preset_names();

// The fields a rule or a layer sets; the others are left as they were beneath.
struct MaterialOverride {
  std::optional<Eigen::Vector3f> albedo;
  std::optional<float> roughness;
  std::optional<float> wetness;
  std::optional<float> forward_scattering;
  std::optional<GroundDetail> detail;
  bool empty() const { return !albedo && !roughness && !wetness && !forward_scattering && !detail; }
};
// A preset as an override that sets every field.
MaterialOverride full_override(const Material& m);

// `under` with the fields `over` sets blended in by weight t in [0, 1].
Material blend(const Material& under, const MaterialOverride& over, float t);

// A range [lo, hi] with soft edges: the weight rises from 0 to 1 over a band
// `band` wide centred on lo and falls back over one centred on hi (smoothstep,
// so the blend has no visible seam). An open side (infinite bound) is 1.
struct SoftRange {
  float lo = -std::numeric_limits<float>::infinity();
  float hi = std::numeric_limits<float>::infinity();
  float band = 0.0f;
  float weight(float x) const;
};

// A material chosen by where the ground lies: weight = opacity x altitude
// weight x slope weight x position weight. Altitude in metres above the DEM's
// datum (without vertical exaggeration), slope in degrees of the unbumped
// terrain, position the topographic position index in metres
// (render/land_form.h: + on ridges, - in gullies).
struct MaterialRule {
  std::string name = "rule";  // its coverage channel (render/coverage.h)
  MaterialOverride material;
  SoftRange altitude;
  SoftRange slope;
  SoftRange position;
  float altitude_jitter = 0.0f;  // metres: ragged altitude bounds (render/land_form.h)
  float opacity = 1.0f;
  // Clumps (render/land_form.h: clump_mask): size 0 covers the whole range;
  // else blobs about clump_size metres across cover clump_cover of it.
  float clump_size = 0.0f;
  float clump_cover = 1.0f;
  // Patches (render/land_form.h: clump_mask with the rule's own weight as the
  // cover): where the soft weight w is between 0 and 1 the rule covers a
  // share w of the ground in patches about patch_size metres across with
  // crisp edges, instead of a translucent w everywhere (snow patches, which
  // end in a line, not a fade); far away the share w alone. 0: soft blend.
  float patch_size = 0.0f;
  float weight(float altitude_m, float slope_deg, float position_m = 0.0f) const;
};

// Kubelka-Munk reflectance of a layer over ground (Kubelka & Munk 1931; the
// closed form in Kortuem 1969, "Reflectance Spectroscopy", eq. 4.45), per
// channel: `infinite` is the layer's reflectance when it is deep (its albedo),
// `under` the ground's, `optical_depth` = S d, the layer's scattering
// coefficient times its thickness. 0 gives the ground, large values the layer.
// Thin snow is translucent: over dark rock a few millimetres read grey.
Eigen::Vector3f layer_albedo(const Eigen::Vector3f& infinite, const Eigen::Vector3f& under,
                             float optical_depth);

// Hermite smoothstep of x between e0 and e1 (a step at e0 when e1 <= e0).
float smoothstep(float e0, float e1, float x);

}  // namespace drift::render
