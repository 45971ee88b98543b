// Frames split across machines: tile i of n is a band of whole rows
// (`drift render --tile i/n`), or block i of a C x R grid of rectangles
// (`--tile i/CxR`, row-major: skies are cheap, mountains are not, so square
// blocks spread the work more evenly than bands), rendered into an EXR that
// knows its place in the frame (EXR data window); `drift merge` joins them into
// exactly the pixels of a single run, since every pixel's random numbers
// depend only on the pixel.
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

// A tile of a frame: block `index` of `columns` x `rows` (bands: 1 column).
struct TileSpec {
  int index = 0, columns = 1, rows = 1;
};
// Parses "i/n" (a band of n) or "i/CxR" (block i of C columns and R rows,
// row-major, 0 <= i < C R); throws drift::Error naming the text and the fix.
TileSpec parse_tile_spec(const std::string& text);

// The pixels of a tile: columns [x.begin, x.end) of rows [y.begin, y.end).
struct TileRect {
  RowRange x, y;
};
// The rectangle of `tile` in a width x height frame; throws drift::Error
// unless it is a whole, non-empty tile (C <= width, R <= height).
TileRect tile_rect(int width, int height, const TileSpec& tile);

// Joins tiles (bands or blocks) into the whole frame. Every pixel must be covered exactly once and
// all tiles must agree on the frame size and channels; `names` (the files)
// name the culprit in errors. Attributes are taken from the first tile.
Image merge_tiles(const std::vector<Image>& tiles, const std::vector<std::filesystem::path>& names);

}  // namespace drift::render
