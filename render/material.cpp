#include "render/material.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace drift::render {

namespace {

struct Preset {
  std::string_view name;
  Material material;
};

// Linear sRGB albedos in the visible (what an RGB render sees), picked inside
// measured ranges. Broadband figures (Hartmann 1994, "Global Physical
// Climatology", table 4.2; Oke 1987, "Boundary Layer Climates", table 1.1)
// overstate vegetation, whose broadband albedo is mostly near infrared.
// - rock: weathered granite and scree, visible reflectance 0.2-0.35 in the
//   USGS spectral library (Kokaly et al. 2017); basalt is far darker (~0.08).
// - dark_rock: the andesite, welded tuff and hornfels of the Hotaka and
//   Yarigatake massifs (Harayama et al. 2000, GSJ 1:50,000 geological sheet
//   "Kamikochi"), dark grey-brown with lichen and oxide films. Measured
//   visible reflectance of these rock types is low: andesite, dacite tuff and
//   hornfels solids 0.08-0.15 at 0.45-0.65 um in the ASTER/ECOSTRESS library
//   (Baldridge et al. 2009, Remote Sens. Environ. 113, 711-715) and the USGS
//   library (Kokaly et al. 2017, splib07); weathering rinds and crustose
//   lichen darken a face further and flatten its spectrum (Watson 1971,
//   Remote Sens. Environ. 2, 95-100; Clark 1999, "Spectroscopy of rocks and
//   minerals", Manual of Remote Sensing vol. 3, ch. 1, sec. 2-3: opaque
//   mafic grains and coatings lower the visible continuum). Luminance 0.09,
//   the lower middle of that range, rising gently from blue to red (iron
//   oxides), so a little warmer than neutral; strongly varied (fresh faces,
//   oxide stains, lichen), fractured relief. (0.12 before read light grey
//   in the default view once the haze of 8-10 km of air was added.)
// - scree: talus of the same rock below the cliffs, fresher broken faces
//   without lichen or rind: a little lighter (0.11-0.16, Baldridge et al.
//   2009 for fresh andesite surfaces), luminance 0.125; granular relief of
//   blocks of decimetres to a metre.
// - meadow: alpine meadow in autumn (sedges and grasses turning straw and
//   russet among Vaccinium): senescent leaves reflect more in the red than
//   green ones (Asner 1998, Remote Sens. Environ. 64, 234-253): ~0.08-0.12.
// - dwarf_pine: Pinus pumila scrub (haimatsu), a dense evergreen needle
//   canopy: conifer canopies reflect 0.03-0.05 in the visible (Betts & Ball
//   1997, J. Geophys. Res. 102(D24), 28901), the darkest green of the range;
//   soft clumps of a few metres.
// - forest: subalpine conifer forest (Abies mariesii, A. veitchii, Tsuga
//   diversifolia) with Erman's birch turning yellow in October: conifer
//   visible albedo 0.03-0.05 (Betts & Ball 1997), a little warmer for the
//   birch; crowns of 3-5 m shade each other (very rough).
// - sand: desert sand 0.25-0.40 (Hartmann), quartz sand tinted yellow by iron
//   oxide coatings; luminance 0.38.
// - mud: bare soil 0.10-0.25 dry, as low as 0.05 dark and wet (Oke); a dark
//   soil (luminance 0.17) under a film of water, wetness 0.8, which darkens
//   it to about 0.11 (render/bsdf.h, Lekner & Dorf 1988) and makes it shine.
// - soil: freshly moved dry mineral soil (sandy loam or loam spoil, a
//   landslide's or a tipped load's deposit): bare dry soils reflect 0.10-0.25
//   (Oke), loams and sandy loams dry and disturbed at the upper end (Post et
//   al. 2000, Soil Sci. Soc. Am. J. 64, 1027-1034: dry soils 0.14-0.35, the
//   lighter the coarser and drier); luminance 0.20, brown. Clods and lumps
//   from a few centimetres to a metre: very rough (Oren-Nayar sigma 0.6, as
//   Oren & Nayar 1994 fit to soils and clay), strong relief over 1 m, a
//   mottled tone. `drift soil`'s deposits render in it ([[objects]] material).
// - grass: green grass in the visible, chlorophyll absorbing blue and red:
//   ~0.05-0.12 with a green peak (luminance 0.10). A canopy is very rough.
// - snow: fresh snow 0.75-0.95 (Hartmann), visible albedo of clean snow
//   0.95-0.98 (Warren 1982, Rev. Geophys. 20(1)); a little blue. Half of its
//   reflection through the forward-scattering lobe of render/bsdf.h.
// Detail (render/ground_detail.h): albedo variation (relative standard
// deviation), rms slope of the sub-cell relief, its largest wavelength and
// the share of it in jointed blocks (rock; Selby 1980, Z. Geomorph. 24,
// 31-51: joint spacing of 0.3-3 m and more in hard rock, the blocks'
// faces the facets a photograph of a ridge shows).
constexpr float kRough = 0.35f;
const std::array<Preset, 11> kPresets = {{
    // name        albedo                  rough wet  fwd   variation bump scale fracture
    {"rock", {{0.30f, 0.28f, 0.25f}, kRough, 0.0f, 0.0f, {0.25f, 0.5f, 4.0f, 0.5f}}},
    {"dark_rock", {{0.10f, 0.088f, 0.074f}, 0.4f, 0.0f, 0.0f, {0.35f, 0.6f, 4.0f, 0.3f}}},
    {"scree", {{0.135f, 0.124f, 0.11f}, 0.5f, 0.0f, 0.0f, {0.2f, 0.35f, 2.0f}}},
    {"meadow", {{0.11f, 0.10f, 0.05f}, 0.7f, 0.0f, 0.0f, {0.3f, 0.2f, 3.0f}}},
    {"dwarf_pine", {{0.028f, 0.042f, 0.022f}, 0.9f, 0.0f, 0.0f, {0.25f, 0.5f, 4.0f}}},
    {"forest", {{0.036f, 0.044f, 0.024f}, 1.0f, 0.0f, 0.0f, {0.35f, 0.6f, 4.5f}}},
    {"sand", {{0.45f, 0.37f, 0.26f}, 0.3f, 0.0f, 0.0f, {0.05f, 0.0f, 4.0f}}},
    {"mud", {{0.20f, 0.16f, 0.12f}, 0.1f, 0.8f, 0.0f, {0.15f, 0.15f, 2.0f}}},
    {"soil", {{0.25f, 0.195f, 0.14f}, 0.6f, 0.0f, 0.0f, {0.2f, 0.35f, 1.0f}}},
    {"grass", {{0.07f, 0.12f, 0.04f}, 0.6f, 0.0f, 0.0f, {0.2f, 0.25f, 3.0f}}},
    {"snow", {{0.90f, 0.92f, 0.95f}, 0.1f, 0.0f, 0.5f, {0.03f, 0.1f, 3.0f}}},
}};

}  // namespace

Material mix(const Material& a, const Material& b, float t) {
  return blend(a, full_override(b), t);
}

std::optional<Material> material_preset(std::string_view name) {
  for (const Preset& p : kPresets)
    if (p.name == name) return p.material;
  return std::nullopt;
}

std::string material_preset_names() {
  std::string out;
  for (const Preset& p : kPresets) out += (out.empty() ? "" : ", ") + std::string(p.name);
  return out;
}

MaterialOverride full_override(const Material& m) {
  return {m.albedo, m.roughness, m.wetness, m.forward_scattering, m.detail};
}

Material blend(const Material& under, const MaterialOverride& over, float t) {
  Material out = under;
  if (over.albedo) out.albedo = under.albedo * (1 - t) + *over.albedo * t;
  if (over.roughness) out.roughness = under.roughness * (1 - t) + *over.roughness * t;
  if (over.wetness) out.wetness = under.wetness * (1 - t) + *over.wetness * t;
  if (over.forward_scattering) {
    out.forward_scattering = under.forward_scattering * (1 - t) + *over.forward_scattering * t;
  }
  if (over.detail) {
    const GroundDetail& a = under.detail;
    const GroundDetail& b = *over.detail;
    out.detail = {a.variation * (1 - t) + b.variation * t, a.bump * (1 - t) + b.bump * t,
                  a.scale * (1 - t) + b.scale * t, a.fracture * (1 - t) + b.fracture * t};
  }
  return out;
}

Eigen::Vector3f layer_albedo(const Eigen::Vector3f& infinite, const Eigen::Vector3f& under,
                             float optical_depth) {
  if (!(optical_depth > 0.0f)) return under;
  Eigen::Vector3f out;
  for (int c = 0; c < 3; ++c) {
    // A layer that absorbs nothing (R_inf = 1) is the limit b -> 0; keep b > 0.
    const float r_inf = std::clamp(infinite[c], 1e-4f, 0.9999f);
    const float r_g = std::clamp(under[c], 0.0f, 1.0f);
    const float a = 0.5f * (1.0f / r_inf + r_inf);  // (S + K) / S
    const float b = std::sqrt(a * a - 1.0f);
    const float x = b * optical_depth;
    // coth x, without overflow for thick layers.
    const float coth = x > 20.0f ? 1.0f : 1.0f / std::tanh(x);
    out[c] = (1.0f - r_g * (a - b * coth)) / (a - r_g + b * coth);
  }
  return out;
}

float smoothstep(float e0, float e1, float x) {
  if (!(e1 > e0)) return x < e0 ? 0.0f : 1.0f;
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3 - 2 * t);
}

float SoftRange::weight(float x) const {
  const float h = 0.5f * band;
  const float rise = std::isfinite(lo) ? smoothstep(lo - h, lo + h, x) : 1.0f;
  const float fall = std::isfinite(hi) ? 1.0f - smoothstep(hi - h, hi + h, x) : 1.0f;
  return rise * fall;
}

float MaterialRule::weight(float altitude_m, float slope_deg, float position_m) const {
  // The same product, left to right, stopped at the first zero (most
  // rules are out of range at most points; the inputs are finite).
  float w = opacity * altitude.weight(altitude_m);
  if (w == 0.0f) return w;
  w *= slope.weight(slope_deg);
  if (w == 0.0f) return w;
  return w * position.weight(position_m);
}

}  // namespace drift::render
