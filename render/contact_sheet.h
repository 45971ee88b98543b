// A contact sheet: several images in a labelled grid, one PNG, for looking at a
// parameter sweep at a glance. Text is drawn with OpenImageIO's FreeType text
// renderer and needs a TrueType font (DejaVu Sans from fonts-dejavu-core).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "render/image.h"
#include "render/tonemap.h"
#include "terrain/progress.h"

namespace drift::render {

struct ContactSheetOptions {
  int columns = 0;                  // images per row, >= 1; 0 = ceil(sqrt(count))
  std::vector<std::string> labels;  // one per image (or empty: no labels)
  std::string title;                // drawn above the grid if not empty
  int padding = 8;                  // pixels around and between cells, [0, 256]
  int font_size = 14;               // label height in pixels, [6, 128]; title is 1.5x
  std::filesystem::path font;       // TrueType font; empty = DejaVu Sans if installed
  DisplayTransform display{0.0, ToneCurve::Clamp};  // linear -> display for every tile
};

// Cell size = the largest image; each image is centred in its cell with its label
// in a band of font_size + padding pixels below it. Sheet size:
//   width  = columns * (cell_w + padding) + padding
//   height = title_band + rows * (cell_h + label_band + padding) + padding
// with label_band = (labels ? font_size + padding : 0) and
// title_band = (title ? 1.5 * font_size + 2 * padding : 0).
// Returns display-linear R, G, B in [0, 1] (write it with ToneCurve::Clamp).
// Throws drift::Error on bad options, a label count that does not match, or a
// missing font when text is needed.
Image contact_sheet(const std::vector<Image>& images, const ContactSheetOptions& options,
                    const ProgressFn& progress = {});

// The font used when options.font is empty, or an empty path if none is found.
std::filesystem::path default_font();

}  // namespace drift::render
