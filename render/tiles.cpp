#include "render/tiles.h"

#include <algorithm>
#include <cstring>
#include <regex>

#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::render {

RowRange tile_rows(int height, int index, int count) {
  if (count < 1 || count > height || index < 0 || index >= count) {
    throw Error("tile " + std::to_string(index) + "/" + std::to_string(count) +
                " does not exist: use i/n with 0 <= i < n <= the image height (" +
                std::to_string(height) + ")");
  }
  auto edge = [&](int i) { return static_cast<int>(static_cast<long long>(i) * height / count); };
  return {edge(index), edge(index + 1)};
}

std::pair<int, int> parse_tile(const std::string& text) {
  std::smatch m;
  if (!std::regex_match(text, m, std::regex(R"((\d{1,6})/(\d{1,6}))"))) {
    throw Error("tile '" + text + "' must be INDEX/COUNT with a 0-based index, e.g. 0/8");
  }
  const int index = std::stoi(m[1]), count = std::stoi(m[2]);
  // A tile that cannot exist in any frame is as much a usage error as "-1/3".
  if (count < 1 || index >= count) {
    throw Error("tile '" + text + "' does not exist: the index counts from 0 to COUNT - 1, e.g. " +
                std::to_string(std::max(count, 1) - 1) + "/" + std::to_string(std::max(count, 1)));
  }
  return {index, count};
}

TileSpec parse_tile_spec(const std::string& text) {
  std::smatch m;
  if (!std::regex_match(text, m, std::regex(R"((\d{1,6})/(\d{1,5})x(\d{1,5}))"))) {
    const auto [index, count] = parse_tile(text);  // bands, or its error
    return {index, 1, count};
  }
  const int index = std::stoi(m[1]), columns = std::stoi(m[2]), rows = std::stoi(m[3]);
  const long long count = static_cast<long long>(columns) * rows;
  if (columns < 1 || rows < 1 || index >= count) {
    throw Error("tile '" + text + "' does not exist: block INDEX/CxR counts from 0 to C R - 1 " +
                "row by row, e.g. " + std::to_string(std::max(count, 1LL) - 1) + "/" +
                std::to_string(std::max(columns, 1)) + "x" + std::to_string(std::max(rows, 1)));
  }
  return {index, columns, rows};
}

TileRect tile_rect(int width, int height, const TileSpec& tile) {
  if (tile.columns > width) {
    throw Error("tile " + std::to_string(tile.index) + "/" + std::to_string(tile.columns) + "x" +
                std::to_string(tile.rows) + " does not exist: use at most as many columns as the " +
                "image is wide (" + std::to_string(width) + ")");
  }
  const int column = tile.index % tile.columns, row = tile.index / tile.columns;
  return {tile_rows(width, column, tile.columns), tile_rows(height, row, tile.rows)};
}

namespace {

// drift render records which scene and settings a tile comes from ("scene");
// tiles of different renders of the same size would otherwise merge silently.
void require_same_scene(const Image& first, const Image& tile, const std::filesystem::path& a,
                        const std::filesystem::path& b) {
  const std::string* x = first.attribute("scene");
  const std::string* y = tile.attribute("scene");
  if ((x == nullptr) != (y == nullptr) || (x && *x != *y)) {
    throw Error(b.string() + " was rendered from another scene or with other settings than " +
                a.string() + " (scene " + (y ? *y : std::string("unknown")) + " against " +
                (x ? *x : std::string("unknown")) + "): merge tiles of one render only");
  }
}

}  // namespace

Image merge_tiles(const std::vector<Image>& tiles,
                  const std::vector<std::filesystem::path>& names) {
  if (tiles.empty()) throw Error("nothing to merge: give the tile EXR files");
  const Image& first = tiles.front();
  const int width = first.frame.full_width, height = first.frame.full_height;
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    const Image& t = tiles[i];
    const std::string name = names.at(i).string();
    if (t.frame.full_width <= 0 || t.frame.full_height <= 0) {
      throw Error(name +
                  " is a whole image, not a tile (render tiles with drift render --tile i/n)");
    }
    if (t.frame.full_width != width || t.frame.full_height != height) {
      throw Error(name + " belongs to a " + std::to_string(t.frame.full_width) + "x" +
                  std::to_string(t.frame.full_height) + " frame, " + names[0].string() + " to a " +
                  std::to_string(width) + "x" + std::to_string(height) +
                  " one: merge tiles of one render only");
    }
    if (t.channels != first.channels) {
      throw Error(name + " has other channels than " + names[0].string() +
                  ": merge tiles of one render only");
    }
    if (t.frame.x < 0 || t.frame.y < 0 || t.frame.x + t.width > width ||
        t.frame.y + t.height > height || t.width < 1 || t.height < 1) {
      throw Error(name + " does not lie inside its frame");
    }
    require_same_scene(first, t, names[0], names.at(i));
  }
  require_memory(static_cast<std::uint64_t>(width) * height * first.channels.size() * sizeof(float),
                 "the merged " + std::to_string(width) + "x" + std::to_string(height) + " frame",
                 "merge fewer channels or a smaller frame");
  // Each row's tiles, by their first column: no two may overlap and together
  // they must span the row.
  std::vector<std::vector<std::size_t>> by_row(static_cast<std::size_t>(height));
  for (std::size_t i = 0; i < tiles.size(); ++i)
    for (int r = 0; r < tiles[i].height; ++r) by_row[tiles[i].frame.y + r].push_back(i);
  // The first row with a gap: its columns (a band's missing rows are named as rows).
  for (int y = 0; y < height; ++y) {
    std::vector<std::size_t>& row = by_row[y];
    std::sort(row.begin(), row.end(),
              [&](std::size_t a, std::size_t b) { return tiles[a].frame.x < tiles[b].frame.x; });
    int next = 0;
    for (std::size_t k = 0; k <= row.size(); ++k) {
      const int x = k < row.size() ? tiles[row[k]].frame.x : width;
      if (x < next) {
        throw Error(names[row[k - 1]].string() + " and " + names[row[k]].string() +
                    " overlap at pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                    "): give each tile once");
      }
      if (x > next) {
        if (next == 0 && x == width) {
          int y1 = y;
          while (y1 + 1 < height && by_row[y1 + 1].empty()) ++y1;
          throw Error("rows " + std::to_string(y) + " to " + std::to_string(y1) + " of the " +
                      std::to_string(width) + "x" + std::to_string(height) +
                      " frame are in no tile: a tile is missing (or failed); render it and merge "
                      "again");
        }
        throw Error("columns " + std::to_string(next) + " to " + std::to_string(x - 1) +
                    " of row " + std::to_string(y) + " of the " + std::to_string(width) + "x" +
                    std::to_string(height) +
                    " frame are in no tile: a tile is missing (or failed); render it and merge "
                    "again");
      }
      if (k < row.size()) next = x + tiles[row[k]].width;
    }
  }
  Image out(width, height, first.channels);
  out.attributes = first.attributes;
  out.header_texts = first.header_texts;  // one render's: the same in every tile
  out.header_matrices = first.header_matrices;
  out.header_vectors = first.header_vectors;
  const std::size_t channels = first.channels.size();
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    const Image& t = tiles[i];
    const std::size_t row_floats = static_cast<std::size_t>(t.width) * channels;
    for (int r = 0; r < t.height; ++r) {
      const std::size_t y = static_cast<std::size_t>(t.frame.y) + static_cast<std::size_t>(r);
      std::memcpy(&out.pixels[(y * width + t.frame.x) * channels],
                  &t.pixels[static_cast<std::size_t>(r) * row_floats], row_floats * sizeof(float));
    }
  }
  return out;
}

}  // namespace drift::render
