// Counter-based random numbers: every value is a pure function of
// (seed, pixel, sample, dimension), so an image is bit-identical whatever the
// thread count, tile size or tile order.
#pragma once

#include <cstdint>

namespace drift::render {

// SplitMix64 finaliser (Steele, Lea & Flood 2014): a strong 64-bit mixer.
inline std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// The random stream of one pixel sample; next() walks its dimensions.
class SampleStream {
 public:
  SampleStream(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample)
      : key_(mix64(mix64(mix64(seed) ^ pixel) ^ sample)) {}

  // Uniform in [0, 1), 24 bits so that the float is exact.
  float next() {
    const std::uint64_t bits = mix64(key_ ^ dimension_++);
    return static_cast<float>(bits >> 40) * (1.0f / 16777216.0f);
  }

 private:
  std::uint64_t key_;
  std::uint64_t dimension_ = 0;
};

}  // namespace drift::render
