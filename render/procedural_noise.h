// Deterministic 2-D noise for detail below the DEM's cell: value noise with
// its analytic gradient (quintic fade, Perlin 2002, "Improving noise"), and
// a sum of octaves filtered by a ray's footprint as a mip-map is: octaves
// whose wavelength the footprint covers are faded out (between 2 and 1
// footprints), so far ground neither shimmers nor changes its mean. What the
// filter removes is returned as the variance of the slopes it took away, for
// the renderer to turn into roughness (LEAN mapping, Olano & Baker 2010).
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace drift::render {

struct NoiseSample {
  float value = 0.0f;               // in [-1, 1], mean 0 over the plane
  Eigen::Vector2f gradient{0, 0};   // d value / d (x, y), per unit of x and y
};

// Value noise on the integer lattice (lattice values uniform in [-1, 1],
// hashed from the cell and `seed`).
NoiseSample value_noise(double x, double y, std::uint64_t seed);

// Measured over 2 x 10^6 random points of value_noise (checked by
// tests/render/ground_detail_test.cpp):
// its standard deviation and the rms length of its gradient per unit.
constexpr float kNoiseStd = 0.4522f;
constexpr float kNoiseGradientRms = 1.2215f;

// Octaves of wavelengths largest, largest/2, ... down to `smallest` (metres),
// each weighted by `amplitude(wavelength)` and faded out by the footprint.
struct Octaves {
  double largest = 4.0;
  double smallest = 0.25;
  std::uint64_t seed = 0;
};

struct FilteredNoise {
  float value = 0.0f;               // sum of kept octaves (amplitude x noise)
  Eigen::Vector2f gradient{0, 0};   // its gradient, per metre
  float lost_slope_variance = 0.0f; // E|gradient|^2 of what the footprint removed
  int octaves = 0;                  // octaves evaluated (cost)
};

// The sum over octaves of amplitude_i x value_noise(p / wavelength_i), with
// amplitude_i = amplitude_at_largest x (wavelength_i / largest)^hurst, each
// octave weighted by w = clamp(wavelength / footprint - 1, 0, 1).
FilteredNoise filtered_noise(double x, double y, const Octaves& octaves, float amplitude_at_largest,
                             float hurst, double footprint);

// The number of octaves from `largest` down to `smallest` (at least 1).
int octave_count(const Octaves& octaves);

}  // namespace drift::render
