// An image as plain data: width x height pixels of named float channels,
// interleaved. Radiance is linear (scene-referred); AOVs ride along as more
// channels ("depth", "normal.X", "albedo.R", ...), as EXR names them.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace drift::render {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::string> channels;  // e.g. {"R", "G", "B"}
  std::vector<float> pixels;          // (y * width + x) * channels.size() + c; row 0 at the top

  // Where this image sits in a larger frame when it is one tile of it (EXR's
  // data window inside its display window); full sizes 0: it is the frame.
  struct Frame {
    int x = 0, y = 0;
    int full_width = 0, full_height = 0;
  } frame;
  // Named text attributes kept in EXR files as "drift:NAME" (e.g. the display
  // settings a tile was rendered with, so `drift merge` can write the PNG).
  std::vector<std::pair<std::string, std::string>> attributes;
  // Header attributes under their own names, for other tools: texts
  // (Cryptomatte's manifest, the CRS), 4x4 matrices as OpenEXR's m44f
  // (worldToCamera; row-major, row vectors) and 3-vectors as v3f.
  std::vector<std::pair<std::string, std::string>> header_texts;
  std::vector<std::pair<std::string, std::array<float, 16>>> header_matrices;
  std::vector<std::pair<std::string, std::array<float, 3>>> header_vectors;
  const std::string* attribute(std::string_view name) const {
    for (const auto& [k, v] : attributes)
      if (k == name) return &v;
    return nullptr;
  }

  Image() = default;
  Image(int width, int height, std::vector<std::string> channel_names, float fill = 0.0f);

  int channel_count() const { return static_cast<int>(channels.size()); }
  // Index of channel `name`, or -1.
  int channel_index(std::string_view name) const;

  float& at(int x, int y, int c) {
    return pixels[(static_cast<std::size_t>(y) * width + x) * channels.size() + c];
  }
  float at(int x, int y, int c) const {
    return pixels[(static_cast<std::size_t>(y) * width + x) * channels.size() + c];
  }
};

// The pixels of `image` in the rectangle at (x, y) of w x h, every channel
// kept; throws drift::Error naming the rectangle when it leaves the image.
Image crop(const Image& image, int x, int y, int w, int h);

}  // namespace drift::render
