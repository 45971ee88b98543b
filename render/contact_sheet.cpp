// Contact sheet layout and text (OpenImageIO ImageBufAlgo::render_text, which
// rasterises TrueType glyphs with FreeType and composites them "over").
#include "render/contact_sheet.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>

#include "terrain/error.h"

namespace drift::render {

namespace {

constexpr float kBackground = 0.05f;  // display-linear grey behind the cells

void draw_text(Image& sheet, const std::filesystem::path& font, int x, int y,
               const std::string& text, int size) {
  if (text.empty()) return;
  OIIO::ImageSpec spec(sheet.width, sheet.height, 3, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf buf(spec, sheet.pixels.data());  // wraps the sheet's pixels, no copy
  const float white[3] = {1.0f, 1.0f, 1.0f};
  if (!OIIO::ImageBufAlgo::render_text(buf, x, y, text, size, font.string(), white,
                                       OIIO::ImageBufAlgo::TextAlignX::Center,
                                       OIIO::ImageBufAlgo::TextAlignY::Top)) {
    throw Error("cannot draw the label '" + text + "' with font " + font.string() + ": " +
                buf.geterror() + " (install fonts-dejavu-core or pass another .ttf font)");
  }
}

// Checks the options against the images; returns the font for the labels
// (empty when nothing is written).
std::filesystem::path check_sheet(const std::vector<Image>& images, const ContactSheetOptions& o,
                                  bool has_labels) {
  if (images.empty()) throw Error("a contact sheet needs at least one image");
  if (!o.labels.empty() && o.labels.size() != images.size()) {
    throw Error(std::to_string(o.labels.size()) + " labels for " + std::to_string(images.size()) +
                " images; give one label per image (separated by '|') or none");
  }
  const int count = static_cast<int>(images.size());
  if (o.columns < 0 || o.columns > count) {
    throw Error("columns " + std::to_string(o.columns) + " must be in [1, " +
                std::to_string(count) + "] (or 0 for automatic)");
  }
  if (o.padding < 0 || o.padding > 256) {
    throw Error("padding " + std::to_string(o.padding) + " must be in [0, 256]");
  }
  if (o.font_size < 6 || o.font_size > 128) {
    throw Error("font size " + std::to_string(o.font_size) + " must be in [6, 128]");
  }
  std::filesystem::path font = o.font.empty() ? default_font() : o.font;
  if ((has_labels || !o.title.empty())) {
    std::error_code ec;
    if (font.empty() || !std::filesystem::is_regular_file(font, ec)) {
      throw Error("no font for the labels" +
                  (o.font.empty() ? std::string() : " (" + o.font.string() + " not found)") +
                  "; install fonts-dejavu-core (scripts/install-deps.sh) or pass --font FILE.ttf");
    }
  }
  return font;
}

// The grid of cells: as many columns as asked (or a square), each cell as
// large as the largest image, with bands for the title and labels.
struct SheetLayout {
  int columns = 1, cell_w = 0, cell_h = 0, pad = 0, label_band = 0, title_size = 0, title_band = 0;
  long long width = 0, height = 0;
};

SheetLayout sheet_layout(const std::vector<Image>& images, const ContactSheetOptions& o,
                         bool has_labels) {
  const int count = static_cast<int>(images.size());
  SheetLayout l;
  l.columns = o.columns > 0 ? o.columns : static_cast<int>(std::ceil(std::sqrt(double(count))));
  const int rows = (count + l.columns - 1) / l.columns;
  for (const Image& im : images) {
    l.cell_w = std::max(l.cell_w, im.width);
    l.cell_h = std::max(l.cell_h, im.height);
  }
  l.pad = o.padding;
  l.label_band = has_labels ? o.font_size + l.pad : 0;
  l.title_size = o.font_size * 3 / 2;
  l.title_band = o.title.empty() ? 0 : l.title_size + 2 * l.pad;
  l.width = static_cast<long long>(l.columns) * (l.cell_w + l.pad) + l.pad;
  l.height =
      l.title_band + static_cast<long long>(rows) * (l.cell_h + l.label_band + l.pad) + l.pad;
  if (l.width > 65535 || l.height > 65535) {
    throw Error("contact sheet of " + std::to_string(l.width) + "x" + std::to_string(l.height) +
                " pixels is too large; use fewer or smaller images");
  }
  return l;
}

// Image `i` tone-mapped into its cell, centred.
void place_image(Image& sheet, const Image& im, int i, int cx, int cy, const SheetLayout& l,
                 const DisplayTransform& display) {
  int ir = im.channel_index("R"), ig = im.channel_index("G"), ib = im.channel_index("B");
  if (ir < 0 || ig < 0 || ib < 0) {
    if (im.channel_count() != 1) {
      throw Error("image " + std::to_string(i + 1) +
                  " of the contact sheet has no R, G, B channels and more than one channel");
    }
    ir = ig = ib = 0;
  }
  const int ox = cx + (l.cell_w - im.width) / 2, oy = cy + (l.cell_h - im.height) / 2;
  for (int y = 0; y < im.height; ++y) {
    for (int x = 0; x < im.width; ++x) {
      sheet.at(ox + x, oy + y, 0) = apply_tone_curve(im.at(x, y, ir), display);
      sheet.at(ox + x, oy + y, 1) = apply_tone_curve(im.at(x, y, ig), display);
      sheet.at(ox + x, oy + y, 2) = apply_tone_curve(im.at(x, y, ib), display);
    }
  }
}

}  // namespace

std::filesystem::path default_font() {
  for (const char* p :
       {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "/usr/share/fonts/TTF/DejaVuSans.ttf",
        "/usr/share/fonts/dejavu/DejaVuSans.ttf"}) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(p, ec)) return p;
  }
  return {};
}

Image contact_sheet(const std::vector<Image>& images, const ContactSheetOptions& o,
                    const ProgressFn& progress) {
  const bool has_labels = std::any_of(o.labels.begin(), o.labels.end(),
                                      [](const std::string& s) { return !s.empty(); });
  const std::filesystem::path font = check_sheet(images, o, has_labels);
  if (progress && !progress(0.0, "contact sheet")) throw Cancelled();
  const SheetLayout l = sheet_layout(images, o, has_labels);
  Image sheet(static_cast<int>(l.width), static_cast<int>(l.height), {"R", "G", "B"}, kBackground);
  if (!o.title.empty())
    draw_text(sheet, font, static_cast<int>(l.width / 2), l.pad, o.title, l.title_size);
  const int count = static_cast<int>(images.size());
  for (int i = 0; i < count; ++i) {
    const int cx = l.pad + (i % l.columns) * (l.cell_w + l.pad);
    const int cy = l.title_band + l.pad + (i / l.columns) * (l.cell_h + l.label_band + l.pad);
    place_image(sheet, images[i], i, cx, cy, l, o.display);
    if (has_labels) {
      draw_text(sheet, font, cx + l.cell_w / 2, cy + l.cell_h + l.pad / 2, o.labels[i],
                o.font_size);
    }
    if (progress && !progress(double(i + 1) / count, "contact sheet")) throw Cancelled();
  }
  if (progress) progress(1.0, "contact sheet");
  return sheet;
}

}  // namespace drift::render
