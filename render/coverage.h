// Per-material coverage AOVs: how much of the ground at a pixel each named
// material of the scene covers, for masks in compositing ("grade the grass,
// not the rock").
//
// The ground's material is a stack (render/surface.h): the base, then rules,
// then layers (snow cover among them, last), each entry blended over what lies beneath with a
// weight w. An entry's coverage is its visible share in that stack, as in an
// image editor's layer stack: putting an entry of weight w on top takes w of
// every share beneath it and gives it to the entry. The shares of a terrain
// point sum to 1. Entries with the same name share a channel ("coverage.rock"
// for a rock base and a rock rule on cliffs).
#pragma once

#include <array>
#include <string>
#include <vector>

namespace drift::render {

// At most this many distinct names (channels) per scene.
constexpr int kMaxCoverage = 8;
using Coverage = std::array<float, kMaxCoverage>;

// Puts an entry of weight w in [0, 1] on top of the stack, in channel `slot`.
inline void cover(Coverage& shares, int slot, float w) {
  for (float& s : shares) s *= 1.0f - w;
  shares[slot] += w;
}

// The channels of a surface's stack: its distinct names in stack order (the
// base first), then those of the object layers, and the channel of every
// entry. On objects only their object layers' channels are set.
struct CoverageChannels {
  std::vector<std::string> names;
  int ground = 0;
  std::vector<int> rules, layers, object_layers;
};

// A surface's channels: coverage_channels() in render/surface.h.

}  // namespace drift::render
