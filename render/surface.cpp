#include "render/surface.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "render/ground_detail.h"
#include "render/land_form.h"
#include "render/snow_flakes.h"
#include "render/tonemap.h"
#include "terrain/angles.h"
#include "terrain/bilinear.h"
#include "terrain/error.h"
#include "terrain/raster_io.h"

namespace drift::render {

float sample_raster(const terrain::HeightField& raster, double x, double y, float outside) {
  const auto& gt = raster.geo().geotransform;
  // North-up rasters only (import makes them so): cell-centre coordinates.
  const double fx = (x - gt[0]) / gt[1] - 0.5, fr = (y - gt[3]) / gt[5] - 0.5;
  if (!(fx >= -0.5 && fr >= -0.5 && fx <= raster.width() - 0.5 && fr <= raster.height() - 0.5))
    return outside;
  const int x0 = static_cast<int>(std::floor(fx)), r0 = static_cast<int>(std::floor(fr));
  const float tx = static_cast<float>(fx - x0), tr = static_cast<float>(fr - r0);
  auto at = [&](int xx, int rr) {
    const float v = raster.clamped(xx, rr);
    return std::isnan(v) ? outside : v;
  };
  return terrain::bilinear_blend(at(x0, r0), at(x0 + 1, r0), at(x0, r0 + 1), at(x0 + 1, r0 + 1), tx,
                                 tr);
}

std::array<terrain::HeightField, 3> read_albedo_map(const std::filesystem::path& path) {
  const terrain::RasterHeader header = terrain::read_raster_header(path);
  if (header.bands != 1 && header.bands < 3) {
    throw Error("albedo map '" + path.string() + "' has " + std::to_string(header.bands) +
                " bands; give an RGB image (3 bands) or a grey one (1 band)");
  }
  const bool encoded = header.data_type == "Byte" || header.data_type == "UInt16";
  const float full = header.data_type == "UInt16" ? 65535.0f : 255.0f;
  std::array<terrain::HeightField, 3> rgb;
  for (int c = 0; c < 3; ++c) {
    terrain::ReadOptions options;
    options.band = header.bands == 1 ? 1 : c + 1;
    rgb[c] = terrain::read_raster(path, options);
    if (encoded) {
      for (float& v : rgb[c].values())
        if (!std::isnan(v)) v = srgb_decode(std::clamp(v / full, 0.0f, 1.0f));
    }
  }
  return rgb;
}

terrain::HeightField add_height_change(const terrain::HeightField& dem,
                                       const terrain::HeightField& metres) {
  terrain::HeightField out = dem;
  for (int row = 0; row < dem.height(); ++row) {
    for (int x = 0; x < dem.width(); ++x) {
      const auto c = dem.geo().cell_center(x, row);
      out(x, row) += std::max(0.0f, sample_raster(metres, c[0], c[1], 0.0f));
    }
  }
  return out;
}

namespace {

// The ground's own material: its preset, with the draped albedo where the
// image covers (x, y).
Material base_material(const TerrainSurface& surface, double x, double y) {
  Material ground = surface.ground;
  if (surface.albedo_map) {
    const auto& map = *surface.albedo_map;
    const float r = sample_raster(map[0], x, y, NAN);
    if (!std::isnan(r)) {
      ground.albedo =
          Eigen::Vector3f(r, sample_raster(map[1], x, y, r), sample_raster(map[2], x, y, r))
              .cwiseMax(0.0f)
              .cwiseMin(1.0f);
    }
  }
  return ground;
}

// A weight in [0, 1] put on top of the stack: the material blended over the
// ground beneath, and its coverage share.
void put_on_top(const MaterialOverride& material, float w, int channel,
                const CoverageChannels* channels, Material& ground, SurfacePoint& p) {
  if (!(w > 0.0f)) return;
  ground = blend(ground, material, w);
  if (channels) cover(p.coverage, channel, w);
}

// The rules over the base, in order (so later ones win where they overlap).
void stack_rules(const TerrainSurface& surface, double x, double y, const Relief& relief,
                 double footprint, const CoverageChannels* channels, Material& ground,
                 SurfacePoint& p) {
  const float position = surface.position ? sample_raster(*surface.position, x, y, 0.0f) : 0.0f;
  float ragged = NAN;  // raggedness(x, y), evaluated once if a rule asks
  for (std::size_t i = 0; i < surface.rules.size(); ++i) {
    const MaterialRule& rule = surface.rules[i];
    if (rule.altitude_jitter > 0.0f && std::isnan(ragged)) ragged = raggedness(x, y, footprint);
    const float altitude = rule.altitude_jitter > 0.0f
                               ? relief.altitude + rule.altitude_jitter * ragged
                               : relief.altitude;
    float w = rule.weight(altitude, relief.slope_deg, position);
    if (rule.clump_size > 0.0f && w > 0.0f)
      w *= clump_mask(x, y, rule.clump_size, rule.clump_cover, 0xc1u + 7919u * i, footprint);
    if (rule.patch_size > 0.0f && w > 0.0f && w < 1.0f)
      w = clump_mask(x, y, rule.patch_size, w, 0x9a7u + 7919u * i, footprint);
    put_on_top(rule.material, w, channels ? channels->rules[i] : 0, channels, ground, p);
  }
}

// A thin layer lets the ground beneath show through (translucency): where
// it lies it is metres / w deep (w is its share of the ground), flakes
// (w below 1) at least a flake deep.
MaterialOverride with_thickness(const MaterialLayer& layer, const Material& beneath, float w,
                                double x, double y) {
  MaterialOverride material = layer.material;
  if (!layer.thickness || !material.albedo || !(w > 0.0f)) return material;
  // Beyond the thickness raster (a layer's `outside` share, e.g. the storm's
  // snow on the surround) the layer is as deep as it needs to be: opaque,
  // not a film 0 m thick through which the bare ground showed.
  const float raster = sample_raster(layer.thickness->metres, x, y, NAN);
  if (std::isnan(raster)) return material;
  const float metres = std::max(raster, 0.0f);
  const float lying = w < 1.0f ? std::max(metres / w, kFlakeDepth) : metres;
  material.albedo =
      layer_albedo(*material.albedo, beneath.albedo, layer.thickness->scattering * lying);
  return material;
}

// The layers over the rules, in order, each by its mask.
void stack_layers(const TerrainSurface& surface, double x, double y, const Relief& relief,
                  const Eigen::Vector3f& normal, double footprint, const CoverageChannels* channels,
                  Material& ground, SurfacePoint& p) {
  for (std::size_t i = 0; i < surface.layers.size(); ++i) {
    const MaterialLayer& layer = surface.layers[i];
    const float mask = std::clamp(sample_raster(layer.mask, x, y, layer.outside), 0.0f, 1.0f);
    const float w = mask * layer.opacity;
    const MaterialOverride material = with_thickness(layer, ground, w, x, y);
    // Below full weight, flakes (render/snow_flakes.h) where the layer asks.
    const float shown =
        layer.flakes ? flake_cover({x, y, relief.z}, normal, w, footprint, relief.ray) : w;
    put_on_top(material, shown, channels ? channels->layers[i] : 0, channels, ground, p);
    if (layer.buries_details && shown > 0.0f) p.buried += shown * (1.0f - p.buried);
  }
}

// A normal-detail tile as bump mapping (ripples: paper 002, section 5): the
// tile's slope at the footprint's level tilts the shading normal p.normal and
// its unresolved variance roughens the surface; it fades under buried ground and on
// steep slopes of the smooth terrain `normal`.
void apply_normal_detail(const NormalDetail& r, double x, double y, const Eigen::Vector3f& normal,
                         double footprint, SurfacePoint& p) {
  // Ripples live on sand: not under snow, not on slip faces.
  const float slope_deg =
      std::acos(std::clamp(normal.z(), -1.0f, 1.0f)) * terrain::kDegreesPerRadian<float>;
  const float keep =
      (1.0f - p.buried) * (1.0f - smoothstep(r.fade_start_deg, r.fade_end_deg, slope_deg));
  if (keep <= 0.0f) return;
  // Ground (x, y) -> tile (u, v): turn by -rotation (the tile is turned clockwise).
  const double a = terrain::radians(r.rotation_deg);
  const double c = std::cos(a), s = std::sin(a);
  const double u = c * x - s * y, v = s * x + c * y;
  const SlopePyramid::Moments m = r.slopes.sample_moments(u, v, footprint);
  const float scale = r.strength * keep;
  const Eigen::Vector2f g_tile = m.slope * scale;
  // The ripple relief the footprint averaged away roughens the sand (LEAN
  // mapping): facets tilted by its rms slope, added in quadrature to the
  // sand's own Oren-Nayar sigma.
  const float rms_slope = std::sqrt(m.variance) * scale;
  const float sigma = std::atan(rms_slope);
  p.material.roughness = std::min(std::hypot(p.material.roughness, sigma), kMaxRoughness);
  // Slope back to ground axes (the inverse rotation).
  const Eigen::Vector2f g(static_cast<float>(c * g_tile.x() + s * g_tile.y()),
                          static_cast<float>(-s * g_tile.x() + c * g_tile.y()));
  // Surface z = Z(x, y) + h(x, y): n ~ (-(Zx + hx), -(Zy + hy), 1), where Z
  // is the surface so far (the terrain, tilted by any detail before).
  const Eigen::Vector3f base = p.normal / p.normal.z();
  p.normal = Eigen::Vector3f(base.x() - g.x(), base.y() - g.y(), 1.0f).normalized();
}

}  // namespace

SurfacePoint shade_terrain(const TerrainSurface& surface, double x, double y,
                           const Eigen::Vector3f& normal, double footprint, const Relief& relief,
                           const CoverageChannels* channels) {
  SurfacePoint p;
  p.normal = normal;
  Material ground = base_material(surface, x, y);
  if (channels) p.coverage[channels->ground] = 1.0f;
  stack_rules(surface, x, y, relief, footprint, channels, ground, p);
  stack_layers(surface, x, y, relief, normal, footprint, channels, ground, p);
  p.material = ground;
  if (normal.z() > 1e-3f)
    for (const NormalDetail& tile : surface.normal_details)
      apply_normal_detail(tile, x, y, normal, footprint, p);
  const DetailedGround detail =
      ground_detail(p.material, x, y, relief.altitude, p.normal, footprint, surface.cell);
  p.material.albedo = detail.albedo;
  p.material.roughness = detail.roughness;
  p.normal = detail.normal;
  return p;
}

CoverageChannels coverage_channels(const TerrainSurface& surface) {
  CoverageChannels c;
  auto channel = [&](const std::string& name) {
    const auto it = std::find(c.names.begin(), c.names.end(), name);
    if (it != c.names.end()) return static_cast<int>(it - c.names.begin());
    if (static_cast<int>(c.names.size()) == kMaxCoverage) {
      throw Error("the ground's materials have more than " + std::to_string(kMaxCoverage) +
                  " names (coverage channels); give rules and layers of one kind the same " +
                  "'name'");
    }
    c.names.push_back(name);
    return static_cast<int>(c.names.size()) - 1;
  };
  c.ground = channel(surface.ground_name);
  for (const MaterialRule& rule : surface.rules) c.rules.push_back(channel(rule.name));
  for (const MaterialLayer& layer : surface.layers) c.layers.push_back(channel(layer.name));
  for (const ObjectLayer& layer : surface.object_layers)
    c.object_layers.push_back(channel(layer.name));
  return c;
}

}  // namespace drift::render
