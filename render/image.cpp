#include "render/image.h"

#include <algorithm>

#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::render {

Image::Image(int w, int h, std::vector<std::string> channel_names, float fill)
    : width(w), height(h), channels(std::move(channel_names)) {
  if (w < 1 || h < 1 || channels.empty()) {
    throw Error("image size " + std::to_string(w) + "x" + std::to_string(h) + " with " +
                std::to_string(channels.size()) + " channel(s) is empty");
  }
  const std::uint64_t bytes =
      static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h) * channels.size() * 4u;
  require_memory(bytes, "an image of " + std::to_string(w) + " x " + std::to_string(h),
                 "choose a smaller size");
  pixels.assign(static_cast<std::size_t>(w) * h * channels.size(), fill);
}

int Image::channel_index(std::string_view name) const {
  auto it = std::find(channels.begin(), channels.end(), name);
  return it == channels.end() ? -1 : static_cast<int>(it - channels.begin());
}

Image crop(const Image& image, int x, int y, int w, int h) {
  // Compared as differences: x + w may overflow an int (a hostile --region).
  if (x < 0 || y < 0 || w < 1 || h < 1 || x > image.width - w || y > image.height - h) {
    throw Error("the region " + std::to_string(w) + "x" + std::to_string(h) + " at (" +
                std::to_string(x) + ", " + std::to_string(y) + ") is not inside the " +
                std::to_string(image.width) + "x" + std::to_string(image.height) + " image");
  }
  Image out(w, h, image.channels);
  const std::size_t row = static_cast<std::size_t>(w) * image.channels.size();
  for (int r = 0; r < h; ++r) {
    const float* from =
        &image.pixels[(static_cast<std::size_t>(y + r) * image.width + x) * image.channels.size()];
    std::copy(from, from + row, out.pixels.begin() + static_cast<std::ptrdiff_t>(r * row));
  }
  return out;
}

}  // namespace drift::render
