// Frames split across machines: tile i of n is a band of whole rows, rendered
// by `drift render --tile i/n` into an EXR that knows its place in the frame
// (EXR data window); `drift merge` joins the bands into exactly the pixels of
// a single run, since every pixel's random numbers depend only on the pixel.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "render/image.h"

namespace drift::render {

struct RowRange {
  int begin = 0, end = 0;  // [begin, end)
};

// Rows of tile `index` (0-based) of `count` bands of a `height`-row frame.
// Throws drift::Error unless 0 <= index < count <= height.
RowRange tile_rows(int height, int index, int count);

// Parses "i/n" (0 <= i < n); throws drift::Error naming the text and the fix.
std::pair<int, int> parse_tile(const std::string& text);

// Joins tiles into the whole frame. Every row must be covered exactly once and
// all tiles must agree on the frame size and channels; `names` (the files)
// name the culprit in errors. Attributes are taken from the first tile.
Image merge_tiles(const std::vector<Image>& tiles, const std::vector<std::filesystem::path>& names);

}  // namespace drift::render
