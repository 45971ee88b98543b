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
    if (t.frame.x != 0 || t.width != width || t.frame.y < 0 || t.frame.y + t.height > height) {
      throw Error(name + " does not lie inside its frame as a band of whole rows");
    }
    require_same_scene(first, t, names[0], names.at(i));
  }
  require_memory(static_cast<std::uint64_t>(width) * height * first.channels.size() * sizeof(float),
                 "the merged " + std::to_string(width) + "x" + std::to_string(height) + " frame",
                 "merge fewer channels or a smaller frame");
  Image out(width, height, first.channels);
  out.attributes = first.attributes;
  out.header_texts = first.header_texts;  // one render's: the same in every tile
  out.header_matrices = first.header_matrices;
  out.header_vectors = first.header_vectors;
  std::vector<int> owner(static_cast<std::size_t>(height), -1);
  const std::size_t row_floats = static_cast<std::size_t>(width) * first.channels.size();
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    const Image& t = tiles[i];
    for (int r = 0; r < t.height; ++r) {
      const int y = t.frame.y + r;
      if (owner[y] >= 0) {
        throw Error("row " + std::to_string(y) + " is in both " + names[owner[y]].string() +
                    " and " + names[i].string() + ": give each tile once");
      }
      owner[y] = static_cast<int>(i);
      std::memcpy(&out.pixels[static_cast<std::size_t>(y) * row_floats],
                  &t.pixels[static_cast<std::size_t>(r) * row_floats], row_floats * sizeof(float));
    }
  }
  const auto hole = std::find(owner.begin(), owner.end(), -1);
  if (hole != owner.end()) {
    const int y0 = static_cast<int>(hole - owner.begin());
    int y1 = y0;
    while (y1 + 1 < height && owner[y1 + 1] < 0) ++y1;
    throw Error("rows " + std::to_string(y0) + " to " + std::to_string(y1) + " of the " +
                std::to_string(width) + "x" + std::to_string(height) +
                " frame are in no tile: a tile is missing (or failed); render it and merge again");
  }
  return out;
}

}  // namespace drift::render
