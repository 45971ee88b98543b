// An image as plain data: width x height pixels of named float channels,
// interleaved. Radiance is linear (scene-referred); AOVs ride along as more
// channels ("depth", "normal.X", "albedo.R", ...), as EXR names them.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace drift::render {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::string> channels;  // e.g. {"R", "G", "B"}
  std::vector<float> pixels;          // (y * width + x) * channels.size() + c; row 0 at the top

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

}  // namespace drift::render
