#include "render/ground_detail.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "render/fast_math.h"
#include "render/procedural_noise.h"
#include "terrain/hash.h"

namespace drift::render {

namespace {

// Seeds of the three noises (fixed: the ground is part of the scene, not of
// the render's sampling).
constexpr std::uint64_t kAlbedoSeed = 0x6a1bed0;
constexpr std::uint64_t kHueSeed = 0x6a1bed1;
constexpr std::uint64_t kReliefSeed = 0x6a1bed2;

// Albedo octaves: 128 m down to 0.5 m, Hurst 0.3.
constexpr Octaves kAlbedoOctaves{128.0, 0.5, kAlbedoSeed};
constexpr float kAlbedoHurst = 0.3f;
// Relief octaves: scale down to scale / 32, height amplitudes growing with
// wavelength^0.6 (Hurst 0.6; natural rock surfaces are self-affine with
// Hurst exponents of about 0.5-0.9, Power & Tullis 1991, J. Geophys. Res.
// 96(B1), 415-424):
// the slope is carried mostly by the small octaves, so the largest
// octave's height (about 0.1 bump x scale) barely tilts a whole cell.
constexpr double kReliefRange = 32.0;
constexpr float kReliefHurst = 0.6f;

// Sum over octaves of (wavelength / largest)^(2 hurst): the variance of the
// octave sum is kNoiseStd^2 a^2 times this.
float octave_energy(const Octaves& o, float hurst) {
  float sum = 0.0f;
  double w = o.largest;
  for (int i = 0; i < octave_count(o); ++i, w *= 0.5)
    sum += static_cast<float>(std::pow(w / o.largest, 2.0 * hurst));
  return sum;
}

// Jointed rock: blocks between joints, each block's face made of creased
// facets, the joints dark (shadowed gaps). Hard rock breaks along joint sets
// a few decimetres to metres apart (Selby 1980, Z. Geomorph. 24, 31-51);
// on a cliff one set lies near the bedding or sheeting, so the blocks stand
// in rows and their tops are ledges. Here: rows `rows` high with jittered
// joints between them, each row cut by cross joints `length` apart at a
// stagger of its own; a block's relief is a roof (or groove) along each of
// its axes, creased at a random point, so each face is four planar facets
// with crisp edges. A roof's slope averages to 0 over its block (r a/r -
// (1 - r) a/(1 - r) = 0) and its height is 0 at the joints, so the mean
// surface over a cell stays the DEM's (tests/render/ground_detail_test.cpp).
constexpr std::uint64_t kJointSeed = 0x6a1bed3;
// Joint darkness and width (fraction of the block's length): shadowed gaps.
constexpr float kJointDarkness = 0.6f;
constexpr float kJointWidth = 0.03f;
// Blocks' length against the relief's largest wavelength, and the larger
// joint sets' (colour only), with their faces' tones (relative rms).
constexpr float kBlockLength = 0.4f;
constexpr float kMassLength = 2.5f;
constexpr float kMassTone = 0.12f;

// A uniform number in [0, 1) from a hash of (i, j, k).
float unit_hash(std::int64_t i, std::int64_t j, std::uint64_t k) {
  const std::uint64_t h = terrain::mix64(
      kJointSeed ^ (static_cast<std::uint64_t>(i) * 0xd1b54a32d192ed03ULL) ^
      (static_cast<std::uint64_t>(j) * 0x9e3779b97f4a7c15ULL) ^ (k * 0xbf58476d1ce4e5b9ULL));
  return static_cast<float>(h >> 40) * (1.0f / 16777216.0f);
}

// The interval [lo, hi) of joints at spacing `step` jittered by +-40 % that
// holds t, and its index (`line` tells the sets of joints apart).
struct Span {
  std::int64_t index;
  double lo, hi;
};
Span joint_span(double t, double step, std::int64_t line, std::uint64_t set) {
  auto joint = [&](std::int64_t k) {
    return (static_cast<double>(k) + 0.8 * (unit_hash(k, line, set) - 0.5)) * step;
  };
  auto k = static_cast<std::int64_t>(std::floor(t / step));
  while (t < joint(k)) --k;
  while (t >= joint(k + 1)) ++k;
  return {k, joint(k), joint(k + 1)};
}

// A roof's slope across a block of width w at position s in [0, 1): creased
// at r, mean square k^2 over the block whatever r, mean 0.
float roof_slope(float s, float r, float k) {
  return s < r ? k * std::sqrt((1.0f - r) / r) : -k * std::sqrt(r / (1.0f - r));
}

struct JointedBlocks {
  Eigen::Vector2f slope{0, 0};
  float lost_variance = 0.0f;
  float albedo_factor = 1.0f;  // the joints' darkening, mean 1
};

// The block of a joint pattern `length` long in rows `rows` high that holds
// (u, v): rows between jittered joints, each row cut by cross joints at a
// stagger of its own; the pattern turned by `angle` (radians: joint sets
// are seldom square to the map or level on a cliff).
struct Block {
  Span row, col;
  float su = 0, sv = 0;  // position across the block, [0, 1) each way
  // Distances (metres) to the joints left, right, below and above, and how
  // open each is (0-1, mostly faint: not every joint is a dark gap).
  double edge[4] = {0, 0, 0, 0};
  float open[4] = {0, 0, 0, 0};
};
// Rows follow bedding or sheeting that is seldom a straight line (on gentle
// ground too, where straight rows read as paving): the row coordinate is
// bent by two octaves of noise along the rows
// (wavelengths 4 and 1.3 block lengths, rms about a quarter of a row), so a
// ledge rises and falls across a face and rows pinch out (Selby 1980:
// sheeting joints follow the surface's curvature). The noise is zero-mean,
// so the rows' mean height and the blocks' share of the relief are kept.
double bent_row(double ru, double rv, double length, double rows, std::uint64_t set) {
  const float wave = 0.55f * value_noise(ru / (4.0 * length), 0.5, set + 5).value +
                     0.25f * value_noise(ru / (1.3 * length), 0.5, set + 6).value;
  return rv + rows * wave;
}

// How open a row joint is varies along it: each stretch of about
// kOpenStretch block lengths takes its own openness (both rows either side
// read the same stretch, so they agree), so a ledge's dark line comes and
// goes instead of running the width of a face.
constexpr double kOpenStretch = 1.7;

Block locate_block(double u, double v, double length, double rows, double angle,
                   std::uint64_t set) {
  const double c = std::cos(angle), s = std::sin(angle);
  const double ru = c * u + s * v;
  const double rv = bent_row(ru, -s * u + c * v, length, rows, set);
  Block b;
  b.row = joint_span(rv, rows, 0, set);
  const double shifted = ru + unit_hash(b.row.index, 0, set + 1) * length;
  b.col = joint_span(shifted, length, b.row.index, set + 2);
  b.su = static_cast<float>((shifted - b.col.lo) / (b.col.hi - b.col.lo));
  b.sv = static_cast<float>((rv - b.row.lo) / (b.row.hi - b.row.lo));
  const double edge[4] = {shifted - b.col.lo, b.col.hi - shifted, rv - b.row.lo, b.row.hi - rv};
  // Each joint's openness from its own index (a row joint's from its
  // stretch along the row too), so both sides of it agree.
  const auto stretch = static_cast<std::int64_t>(std::floor(ru / (kOpenStretch * length)));
  const float h[4] = {unit_hash(b.col.index, b.row.index, set + 3),
                      unit_hash(b.col.index + 1, b.row.index, set + 3),
                      unit_hash(b.row.index, stretch, set + 4),
                      unit_hash(b.row.index + 1, stretch, set + 4)};
  for (int i = 0; i < 4; ++i) b.edge[i] = edge[i], b.open[i] = h[i] * h[i];
  return b;
}

// Kept share of a pattern `size` across at a footprint: whole above two
// footprints, gone below one (as the octaves fade).
float kept(double size, double footprint) {
  return footprint > 0.0 ? static_cast<float>(std::clamp(size / footprint - 1.0, 0.0, 1.0)) : 1.0f;
}

// Dark joints: a Gaussian line along each edge of a block, kJointWidth x
// length wide and as dark as the joint is open, averaged over the footprint
// across it (a box F wide: (w sqrt(pi) / 2F) [erf((d + F/2) / w) - erf((d -
// F/2) / w)]) and faded into its mean as the blocks are; normalised so the
// mean over the blocks is 1 (E[open] = 1/3).
float joint_darkening(const Block& b, double length, double rows, double footprint, float keep) {
  const double width = kJointWidth * length;
  const double half = 0.5 * footprint;
  double line = 0.0;
  for (int i = 0; i < 4; ++i) {
    if (b.open[i] == 0.0f) continue;
    const double d = b.edge[i];
    line += b.open[i] * (half > 0.05 * width
                             ? width * std::sqrt(std::numbers::pi) / (4.0 * half) *
                                   (std::erf((d + half) / width) - std::erf((d - half) / width))
                             : std::exp(-(d * d) / (width * width)));
  }
  // Mean of the lines over a block: perimeter x width x sqrt(pi) / 2 / area / 3.
  const double mean = (length + rows) * width * std::sqrt(std::numbers::pi) / (length * rows) / 3.0;
  const double dark = std::min(1.0, kJointDarkness * (keep * line + (1.0 - keep) * mean));
  return static_cast<float>((1.0 - dark) / (1.0 - kJointDarkness * mean));
}

// Blocks about `length` across with rms slope `rms` on the plane (u, v);
// `layered`: v is up a cliff (rows half as high as long, the relief mostly
// across the rows: ledges), else a map plane (near-square blocks).
JointedBlocks jointed_blocks(double u, double v, float length, float rms, bool layered,
                             double footprint) {
  JointedBlocks out;
  const double rows = (layered ? 0.5 : 0.8) * length;
  const float keep = kept(rows, footprint);
  out.lost_variance = (1.0f - keep * keep) * rms * rms;
  if (keep <= 0.0f) return out;
  const float angle = layered ? 0.21f : 0.61f;
  const Block b = locate_block(u, v, length, rows, angle, 1);
  // Share of the variance across the rows: ledges on a cliff.
  const float across = layered ? 0.75f : 0.5f;
  auto hash = [&](std::uint64_t k) { return unit_hash(b.col.index, b.row.index, k); };
  auto amplitude = [&](std::uint64_t k, float share) {  // uniform, mean square share rms^2
    return (2.0f * hash(k) - 1.0f) * std::sqrt(3.0f * share) * rms;
  };
  const float ru = 0.3f + 0.4f * hash(4), rv = 0.3f + 0.4f * hash(5);
  // A roof's slope is set, not its height: mean square rms^2 whatever the
  // block's jittered size. Back from the pattern's turned axes to (u, v).
  const float gu = roof_slope(b.su, ru, amplitude(6, 1.0f - across));
  const float gv = roof_slope(b.sv, rv, amplitude(7, across));
  const float c = std::cos(angle), s = std::sin(angle);
  out.slope = keep * Eigen::Vector2f(c * gu - s * gv, s * gu + c * gv);
  out.albedo_factor = joint_darkening(b, length, rows, footprint, keep);
  return out;
}

// The larger joint sets, in colour only (so the mean surface stays the
// DEM's): blocks kMassLength x the relief's scale, each face a tone of its
// own (fresh, stained or lichen-grown: +-kMassTone, mean 1), with dark
// joints between; on a cliff in rows (the ledges' lines). What a photograph
// of a ridge from a few hundred metres shows as its jointing.
float joint_tone(double u, double v, float scale, bool layered, double footprint) {
  const double length = kMassLength * scale;
  const double rows = (layered ? 0.5 : 0.8) * length;
  const float keep = kept(rows, footprint);
  if (keep <= 0.0f) return 1.0f;
  const Block b = locate_block(u + 5171.3, v + 2237.9, length, rows, layered ? -0.27 : 1.13, 11);
  const float tone =
      kMassTone * std::sqrt(3.0f) * (2.0f * unit_hash(b.col.index, b.row.index, 12) - 1.0f);
  return (1.0f + keep * tone) * joint_darkening(b, length, rows, footprint, keep);
}

}  // namespace

float albedo_factor(const GroundDetail& detail, double x, double y, double footprint) {
  if (!(detail.variation > 0.0f)) return 1.0f;
  static const float energy = octave_energy(kAlbedoOctaves, kAlbedoHurst);
  const float amplitude = detail.variation / (kNoiseStd * std::sqrt(energy));
  const FilteredNoise n = filtered_noise(x, y, kAlbedoOctaves, amplitude, kAlbedoHurst, footprint);
  return std::clamp(1.0f + n.value, 0.2f, 2.0f);
}

DetailSlope detail_slope(const GroundDetail& detail, double x, double y, double footprint,
                         bool layered) {
  DetailSlope out;
  if (!(detail.bump > 0.0f) || !(detail.scale > 0.0f)) return out;
  const float fracture = std::clamp(detail.fracture, 0.0f, 1.0f);
  const Octaves octaves{detail.scale, detail.scale / kReliefRange, kReliefSeed};
  // Height amplitude of the largest octave for an rms slope `bump` over the
  // noise's share (1 - fracture) of the variance: octave i's rms slope is
  // a (w_i / scale)^(H - 1) kNoiseGradientRms / scale.
  static const float energy = octave_energy(octaves, kReliefHurst - 1.0f);
  const float amplitude = std::sqrt(1.0f - fracture) * detail.bump * detail.scale /
                          (kNoiseGradientRms * std::sqrt(energy));
  const FilteredNoise n = filtered_noise(x, y, octaves, amplitude, kReliefHurst, footprint);
  out.slope = n.gradient;
  out.lost_variance = n.lost_slope_variance;
  if (fracture > 0.0f) {
    const JointedBlocks b = jointed_blocks(x, y, kBlockLength * detail.scale,
                                           std::sqrt(fracture) * detail.bump, layered, footprint);
    out.slope += b.slope;
    out.lost_variance += b.lost_variance;
    out.joint_factor = b.albedo_factor * joint_tone(x, y, detail.scale, layered, footprint);
  }
  return out;
}

namespace {

// Triplanar projection (Geiss 2007, GPU Gems 3, ch. 1 "Generating complex
// procedural terrains using the GPU"): the noise is read on the three axis
// planes and blended by how squarely the surface faces each, so a steep face
// gets its detail from a vertical plane instead of the map's plane stretched
// down its fall line (streaks). A plane counts only where its axis is within
// ~66 degrees of the normal (|n_i| > 0.4), weight (|n_i| - 0.4)^2: gentle
// ground (up to ~24-34 degrees) reads the map's plane alone, exactly as
// before. Blends are divided by the root of the summed squared weights so a
// blend of independent planes keeps one plane's variance.
constexpr float kPlaneDead = 0.4f;

struct Planes {
  // 0: map plane (x, y), axis z; 1: (y, z), axis x; 2: (x, z), axis y.
  float w[3] = {0, 0, 0};
  bool map_only = true;
};

Planes plane_weights(const Eigen::Vector3f& n) {
  Planes p;
  const float a[3] = {std::abs(n.z()), std::abs(n.x()), std::abs(n.y())};
  float sum2 = 0.0f;
  for (int i = 0; i < 3; ++i) {
    const float e = std::max(a[i] - kPlaneDead, 0.0f);
    p.w[i] = e * e;
    sum2 += p.w[i] * p.w[i];
  }
  p.map_only = p.w[1] == 0.0f && p.w[2] == 0.0f;
  for (float& w : p.w) w /= std::sqrt(sum2);
  return p;
}

// Plane i's coordinates of (x, y, z), each plane shifted so that the three
// noises are independent.
Eigen::Vector2d plane_uv(int i, double x, double y, double z) {
  if (i == 0) return {x, y};
  if (i == 1) return {y + 1531.7, z + 2711.3};
  return {x + 3917.1, z + 4409.9};
}

// The albedo factors (variation, joints) and the bumped normal of a face
// steep enough for the vertical planes, whose second axis is up the face.
void triplanar_detail(const GroundDetail& d, const Planes& planes, double x, double y, double z,
                      const Eigen::Vector3f& normal, double footprint, float& factor, float& joints,
                      DetailedGround& out) {
  float f = 0.0f, lost = 0.0f, dark = 0.0f;
  Eigen::Vector3f tilt(0, 0, 0);
  const float axis[3] = {std::abs(normal.z()), std::abs(normal.x()), std::abs(normal.y())};
  for (int i = 0; i < 3; ++i) {
    if (planes.w[i] == 0.0f) continue;
    const Eigen::Vector2d uv = plane_uv(i, x, y, z);
    f += planes.w[i] * (albedo_factor(d, uv.x(), uv.y(), footprint) - 1.0f);
    if (!(d.bump > 0.0f)) continue;
    const DetailSlope s = detail_slope(d, uv.x(), uv.y(), footprint, i != 0);
    dark += planes.w[i] * (s.joint_factor - 1.0f);
    // The relief's gradient in plane i, as a tilt across the plane's axis
    // (for the map plane n - n_z (hx, hy, 0), the heightfield's bump).
    const Eigen::Vector3f g = i == 0   ? Eigen::Vector3f(s.slope.x(), s.slope.y(), 0.0f)
                              : i == 1 ? Eigen::Vector3f(0.0f, s.slope.x(), s.slope.y())
                                       : Eigen::Vector3f(s.slope.x(), 0.0f, s.slope.y());
    tilt += planes.w[i] * axis[i] * g;
    lost += planes.w[i] * planes.w[i] * s.lost_variance;
  }
  factor = std::clamp(1.0f + f, 0.2f, 2.0f);
  joints = std::clamp(1.0f + dark, 0.2f, 2.0f);
  if (d.bump > 0.0f) {
    out.normal = (normal - tilt).normalized();
    out.roughness = lean_roughness(out.roughness, lost);
  }
}

}  // namespace

float lean_roughness(float roughness, float lost_slope_variance) {
  const float sigma = fast_atan_positive(std::sqrt(std::max(lost_slope_variance, 0.0f)));
  return std::min(std::sqrt(roughness * roughness + sigma * sigma), kMaxRoughness);
}

float relief_scale(const GroundDetail& detail, double cell) {
  return cell > 0.0 ? std::min(detail.scale, static_cast<float>(cell)) : detail.scale;
}

DetailedGround ground_detail(const Material& material, double x, double y, double z,
                             const Eigen::Vector3f& normal, double footprint, double cell) {
  GroundDetail d = material.detail;
  d.scale = relief_scale(d, cell);
  DetailedGround out{material.albedo, normal, material.roughness};
  const Planes planes = plane_weights(normal);
  float f = 1.0f, joints = 1.0f;
  if (!planes.map_only && (d.variation > 0.0f || d.bump > 0.0f)) {
    triplanar_detail(d, planes, x, y, z, normal, footprint, f, joints, out);
    if (!(d.variation > 0.0f)) f = 1.0f;
  } else {
    if (d.variation > 0.0f) f = albedo_factor(d, x, y, footprint);
    if (d.bump > 0.0f && normal.z() > 1e-3f) {
      const DetailSlope s = detail_slope(d, x, y, footprint);
      joints = s.joint_factor;
      // Surface z = Z(x, y) + h(x, y): n ~ (-(Zx + hx), -(Zy + hy), 1).
      const Eigen::Vector3f base = normal / normal.z();
      out.normal =
          Eigen::Vector3f(base.x() - s.slope.x(), base.y() - s.slope.y(), 1.0f).normalized();
      out.roughness = lean_roughness(material.roughness, s.lost_variance);
    }
  }
  if (d.variation > 0.0f) {
    // Brightness over all octaves, and a weaker warm-cold hue shift (oxide
    // stains against grey lichen, sun-dried against green growth), the hue
    // on the map's plane only (it is weak and broad).
    const float hue =
        0.12f * d.variation *
        filtered_noise(x, y, {64.0, 8.0, kHueSeed}, 1.0f / kNoiseStd, 0.0f, footprint).value /
        2.0f;  // 4 octaves of equal amplitude: a standard deviation of 1
    out.albedo = (material.albedo * f)
                     .cwiseProduct(Eigen::Vector3f(1.0f + hue, 1.0f, 1.0f - hue))
                     .cwiseMax(0.0f)
                     .cwiseMin(0.98f);
  }
  if (joints != 1.0f) out.albedo = (out.albedo * joints).cwiseMin(0.98f);
  return out;
}

}  // namespace drift::render
