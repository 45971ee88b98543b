// Counter-based random numbers: every value is a pure function of
// (seed, pixel, sample, dimension), so an image is bit-identical whatever the
// thread count, tile size or tile order.
#pragma once

#include <cstdint>

#include "terrain/hash.h"

namespace drift::render {

// The random stream of one pixel sample; next() walks its dimensions.
class SampleStream {
 public:
  SampleStream(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample)
      : key_(terrain::mix64(terrain::mix64(terrain::mix64(seed) ^ pixel) ^ sample)) {}

  // Uniform in [0, 1), 24 bits so that the float is exact.
  float next() { return terrain::unit_float(terrain::mix64(key_ ^ dimension_++)); }

 private:
  std::uint64_t key_;
  std::uint64_t dimension_ = 0;
};

}  // namespace drift::render
