// The sample numbers of one pixel sample: Owen-scrambled Sobol points
// (render/sobol.h), every value a pure function of (seed, pixel, sample,
// dimension), so an image is bit-identical whatever the thread count, tile
// size or tile order, and a pixel may stop after any number of samples
// (adaptive sampling) with every power-of-two prefix still stratified.
//
// Burley 2020 ("Practical Hash-based Owen Scrambling", section 5): each
// request (a 1-D, 2-D or 4-D set of dimensions) is padded to its own 4-D
// Sobol sequence, shuffled by an Owen scramble of the sample index and
// Owen-scrambled per coordinate, all seeded by a hash of (seed, pixel, set).
// Within a set the samples of a pixel are a (0,m,2)-net in the first two
// coordinates; sets and pixels are decorrelated by their seeds, so the
// integrator must draw the same sets in the same order in every sample of a
// pixel (render/path_tracer.cpp takes a fixed number per vertex, skipping
// those a sample does not use) for each set to stand for one integral. The
// coordinates of a set are independent of how many are taken: next2d() gives
// the first two of what next4d() would.
#pragma once

#include <array>
#include <cstdint>

#include "render/sobol.h"
#include "terrain/hash.h"

namespace drift::render {

class SampleStream {
 public:
  SampleStream(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample)
      : pixel_key_(terrain::mix64(terrain::mix64(seed) ^ pixel)),
        index_(static_cast<std::uint32_t>(sample)) {}

  // The next set of dimensions, uniform in [0, 1)^n, 24 bits each (exact floats).
  float next1d() { return next<1>()[0]; }
  std::array<float, 2> next2d() { return next<2>(); }
  std::array<float, 4> next4d() { return next<4>(); }
  // Passes over a set that this sample does not use, at no cost; the next
  // set is the one it would have been.
  void skip() { ++set_; }

 private:
  template <int N>
  std::array<float, N> next() {
    // One 64-bit key per set: its low half shuffles the index, each
    // coordinate's scramble seed is hashed from it.
    const std::uint64_t key = terrain::mix64(pixel_key_ ^ (0x9e3779b97f4a7c15ULL * ++set_));
    const std::uint32_t shuffled = sobol::owen_scramble(index_, static_cast<std::uint32_t>(key));
    std::array<float, N> u{};
    for (int d = 0; d < N; ++d) {
      const auto seed = static_cast<std::uint32_t>(terrain::mix64(key + static_cast<unsigned>(d)));
      u[d] = sobol::to_unit_float(sobol::owen_scramble(sobol::sample_bits(shuffled, d), seed));
    }
    return u;
  }

  std::uint64_t pixel_key_;
  std::uint32_t index_;
  std::uint64_t set_ = 0;
};

}  // namespace drift::render
