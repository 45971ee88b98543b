#include "render/procedural_noise.h"

#include <algorithm>
#include <cmath>

#include "terrain/hash.h"

namespace drift::render {

namespace {

// Lattice value in [-1, 1] of cell (i, j): one SplitMix finalisation of the
// cell's two odd-constant multiples (Weyl sequences) and the seed, cheap and
// uncorrelated enough for noise; `key` is seed ^ i kLatticeX ^ j kLatticeY.
constexpr std::uint64_t kLatticeX = 0xd1b54a32d192ed03ULL;
constexpr std::uint64_t kLatticeY = 0x9e3779b97f4a7c15ULL;
inline float lattice_value(std::uint64_t key) {
  return static_cast<float>(terrain::mix64(key) >> 40) * (2.0f / 16777216.0f) - 1.0f;
}

// Quintic fade 6t^5 - 15t^4 + 10t^3 and its derivative (Perlin 2002): the
// gradient is continuous across cells.
float fade(float t) { return t * t * t * (t * (6.0f * t - 15.0f) + 10.0f); }
float fade_derivative(float t) { return 30.0f * t * t * (t - 1.0f) * (t - 1.0f); }

// floor(x) for |x| < 2^62, exact: the baseline x86-64 (SSE2) has no
// rounding instruction, and std::floor there is a libm call that cost a
// fifth of value_noise.
inline double fast_floor(double x) {
  const auto t = static_cast<double>(static_cast<std::int64_t>(x));  // towards 0
  return t > x ? t - 1.0 : t;
}

// value_noise, inlined into the octave loop below.
[[gnu::always_inline]] inline NoiseSample lattice_noise(double x, double y, std::uint64_t seed) {
  const bool in_range = std::abs(x) < 4e18 && std::abs(y) < 4e18;  // else libm's (NaN, huge)
  const double fx = in_range ? fast_floor(x) : std::floor(x);
  const double fy = in_range ? fast_floor(y) : std::floor(y);
  const auto i = static_cast<std::int64_t>(fx), j = static_cast<std::int64_t>(fy);
  const float tx = static_cast<float>(x - fx), ty = static_cast<float>(y - fy);
  // The four corners' keys, the products by the Weyl constants shared ((i + 1) k = i k + k, modulo
  // 2^64 as there).
  const std::uint64_t xi = static_cast<std::uint64_t>(i) * kLatticeX, xi1 = xi + kLatticeX;
  const std::uint64_t yj = seed ^ (static_cast<std::uint64_t>(j) * kLatticeY);
  const std::uint64_t yj1 = seed ^ (static_cast<std::uint64_t>(j) * kLatticeY + kLatticeY);
  const float a = lattice_value(yj ^ xi), b = lattice_value(yj ^ xi1);
  const float c = lattice_value(yj1 ^ xi), d = lattice_value(yj1 ^ xi1);
  const float u = fade(tx), v = fade(ty);
  const float k = a - b - c + d;
  NoiseSample s;
  s.value = a + (b - a) * u + (c - a) * v + k * u * v;
  s.gradient = {fade_derivative(tx) * ((b - a) + k * v), fade_derivative(ty) * ((c - a) + k * u)};
  return s;
}

// 2^-hurst, the amplitude ratio from one octave to the next: the Hurst
// exponents the renderer uses, computed once (std::exp2 in every call was
// 1 % of the default frame); any other is computed.
float octave_ratio(float hurst) {
  static const float h00 = std::exp2(-0.0f), h03 = std::exp2(-0.3f), h05 = std::exp2(-0.5f),
                     h06 = std::exp2(-0.6f);
  if (hurst == 0.5f) return h05;
  if (hurst == 0.3f) return h03;
  if (hurst == 0.6f) return h06;
  if (hurst == 0.0f) return h00;
  return std::exp2(-hurst);
}

}  // namespace

NoiseSample value_noise(double x, double y, std::uint64_t seed) {
  return lattice_noise(x, y, seed);
}

int octave_count(const Octaves& o) {
  int n = 1;
  for (double w = o.largest * 0.5; w >= o.smallest * (1.0 - 1e-9); w *= 0.5) ++n;
  return n;
}

FilteredNoise filtered_noise(double x, double y, const Octaves& o, float amplitude_at_largest,
                             float hurst, double footprint) {
  // Octave i has wavelength largest / 2^i; octaves after the first while the
  // wavelength is at least `smallest` (octave_count's rule, counted here).
  // Products by the frequency and the footprint's inverse in place of five
  // divisions an octave (the noise was 8 % of the default frame).
  FilteredNoise out;
  const double last = o.smallest * (1.0 - 1e-9);
  const double inverse_footprint = footprint > 0.0 ? 1.0 / footprint : 0.0;
  double wavelength = o.largest, frequency = 1.0 / o.largest;
  const float ratio = octave_ratio(hurst);
  float amplitude = amplitude_at_largest;
  for (int i = 0; i == 0 || wavelength >= last;
       ++i, wavelength *= 0.5, frequency *= 2.0, amplitude *= ratio) {
    // Kept whole above two footprints, gone below one (a mip-map's blend).
    const float keep =
        footprint > 0.0
            ? static_cast<float>(std::clamp(wavelength * inverse_footprint - 1.0, 0.0, 1.0))
            : 1.0f;
    const float per_metre = amplitude * static_cast<float>(frequency);
    const float slope_rms = per_metre * kNoiseGradientRms;
    // What the filter took of this octave: its share of the slope variance.
    out.lost_slope_variance += (1.0f - keep * keep) * slope_rms * slope_rms;
    if (keep <= 0.0f) continue;
    // Each octave its own lattice (seed + i), shifted so lattices do not align.
    const NoiseSample n =
        lattice_noise(x * frequency + 0.37 * i, y * frequency + 0.71 * i, o.seed + 7919u * i);
    out.value += keep * amplitude * n.value;
    out.gradient += (keep * per_metre) * n.gradient;
    ++out.octaves;
  }
  return out;
}

}  // namespace drift::render
