// Counter-based randomness: every random value is a pure function of a seed
// and the counters that name it (cell, pixel, sample, step, dimension), so
// results do not depend on the thread count, the tile split or the order of
// work. Every module draws from these.
#pragma once

#include <cstdint>

namespace drift::terrain {

// The SplitMix64 finaliser (Steele, Lea & Flood 2014, "Fast splittable
// pseudorandom number generators"): a strong 64-bit mixer; chain it over
// seed ^ counter to key a value by several counters.
inline std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Uniform double in [0, 1) from the top 53 bits of a mixed value (exact).
inline double unit_double(std::uint64_t bits) {
  return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

// Uniform float in [0, 1) from the top 24 bits of a mixed value (exact).
inline float unit_float(std::uint64_t bits) {
  return static_cast<float>(bits >> 40) * (1.0f / 16777216.0f);
}

}  // namespace drift::terrain
