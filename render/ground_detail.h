// Ground below the DEM's cell: per material (Material::detail), a relief of
// procedural octaves bump-mapped onto the smooth DEM surface and a variation
// of the albedo, both deterministic functions of the ground position and both
// filtered by the ray's footprint (render/procedural_noise.h).
//
// | field     | meaning                                               | unit     |
// |-----------|-------------------------------------------------------|----------|
// | variation | relative standard deviation of the albedo             | fraction |
// | bump      | rms slope of the relief when every octave is resolved | tan      |
// | scale     | wavelength of the relief's largest octave (<= a cell) | metres   |
//
// What keeps the DEM's meaning: the relief's octaves are zero-mean value noise
// of wavelengths from `scale` down to scale / 32, so its slope averaged over
// a cell is ~0 and the mean surface is the DEM's (tested by averaging over
// footprints); material rules and stage products see the unbumped slope.
// Octaves smaller than the footprint are faded out rather than sampled (no
// shimmer), and the slope variance they carried becomes Oren-Nayar roughness
// (LEAN mapping, Olano & Baker 2010), so far ground keeps its matte, rough
// look. The albedo varies over octaves of 128 m down to 0.5 m with more
// weight on the large ones (Hurst exponent 0.3), so a far range shows
// patches of lighter and darker rock and near ground a finer mottle; the
// variation is a factor of mean 1, so a material's mean albedo is kept.
// Rock (GroundDetail::fracture > 0) breaks into jointed blocks: small ones
// (0.4 x scale) carry that share of the relief as creased facets whose
// slope averages to 0 over each block, larger ones (2.5 x scale) a tone
// each, both with dark joints between; on cliffs in dipping rows (ledges).
// See ground_detail.cpp and docs/rendering.md.
#pragma once

#include "render/material.h"

namespace drift::render {

// Albedo (variation) and shading normal (relief) of a point of ground.
struct DetailedGround {
  Eigen::Vector3f albedo;
  Eigen::Vector3f normal;
  float roughness;
};

// `material` at ground point (x, y, z) (CRS metres, z the altitude) with
// smooth unit normal `normal` (z up), seen by a footprint `footprint` metres
// wide. Faces steeper than ~24-34 degrees read their detail triplanar (from
// the vertical planes too, see ground_detail.cpp), so it is not stretched
// down their fall line; gentler ground reads the map's plane alone.
// `cell`: the DEM's cell (m; 0: not known). The relief is what the DEM does
// not resolve, so its largest wavelength is the smaller of the preset's scale
// and the cell (relief_scale): a 10 m mountain DEM keeps its presets' metres
// of relief, a 1 cm grid of a footprint gets only sub-centimetre grain, not a
// mountainside's bumps at the size of a print. The albedo's mottle is stated
// in metres (128 m to 0.5 m) and stays so at any cell.
DetailedGround ground_detail(const Material& material, double x, double y, double z,
                             const Eigen::Vector3f& normal, double footprint, double cell = 0.0);

// A roughness (Oren-Nayar sigma, radians) with the relief's slope variance
// that a footprint filtered away added (LEAN mapping: facets tilted by its
// rms slope, in quadrature): min(hypot(roughness, atan(sqrt(variance))),
// kMaxRoughness), with render/fast_math.h's arctangent.
float lean_roughness(float roughness, float lost_slope_variance);

// The largest wavelength of the relief (m) on a DEM of cells `cell` m (0: not
// known, the preset's scale).
float relief_scale(const GroundDetail& detail, double cell);

// The relief's slope (dh/dx, dh/dy) and the slope variance the footprint
// filtered away (for tests and the shading above).
// `layered`: the plane's second axis is up a cliff (jointed blocks stand in
// rows, their tops ledges); false for the map's plane. joint_factor is the
// albedo factor (mean 1) of the dark joints between blocks.
struct DetailSlope {
  Eigen::Vector2f slope{0, 0};
  float lost_variance = 0.0f;
  float joint_factor = 1.0f;
};
DetailSlope detail_slope(const GroundDetail& detail, double x, double y, double footprint,
                         bool layered = false);

// The albedo factor (mean 1) at (x, y) for a footprint.
float albedo_factor(const GroundDetail& detail, double x, double y, double footprint);

}  // namespace drift::render
