// Contact sheet layout and text (OpenImageIO ImageBufAlgo::render_text, which
// rasterises TrueType glyphs with FreeType and composites them "over").
#include "render/contact_sheet.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>

#include "terrain/error.h"
#include "terrain/memory.h"

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

// OpenImageIO rasterises a text whole before compositing it: a very long text
// needs gigabytes (and once crashed with SIGFPE when that failed). A text is
// refused if it is wider than the largest sheet (65535 pixels) or its raster
// does not fit in memory; narrower ones are drawn and cut at the sheet's edge.
void require_text_fits(const std::string& text, const std::string& what,
                       const std::filesystem::path& font, int size) {
  constexpr long long kWidest = 65535;
  if (text.empty()) return;
  const auto too_wide = [&](long long pixels) {
    return Error(what + " is about " + std::to_string(pixels) + " pixels wide, more than the " +
                 std::to_string(kWidest) + " of the largest sheet; shorten it");
  };
  // A cheap bound before measuring: few glyphs are wider than twice their size.
  if (static_cast<long long>(text.size()) * size > 2 * kWidest * 16) {
    throw too_wide(static_cast<long long>(text.size()) * size / 2);
  }
  const OIIO::ROI box = OIIO::ImageBufAlgo::text_size(text, size, font.string());
  if (!box.defined()) return;
  if (box.width() > kWidest) throw too_wide(box.width());
  require_memory(static_cast<std::uint64_t>(box.width()) * box.height() * 4 * sizeof(float),
                 "the text of " + what, "shorten it or use a smaller --font-size");
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
  const bool has_labels = std::any_of(o.labels.begin(), o.labels.end(),
                                      [](const std::string& s) { return !s.empty(); });
  std::filesystem::path font = o.font.empty() ? default_font() : o.font;
  if ((has_labels || !o.title.empty())) {
    std::error_code ec;
    if (font.empty() || !std::filesystem::is_regular_file(font, ec)) {
      throw Error("no font for the labels" +
                  (o.font.empty() ? std::string() : " (" + o.font.string() + " not found)") +
                  "; install fonts-dejavu-core (scripts/install-deps.sh) or pass --font FILE.ttf");
    }
  }
  if (progress && !progress(0.0, "contact sheet")) throw Cancelled();

  const int columns =
      o.columns > 0 ? o.columns : static_cast<int>(std::ceil(std::sqrt(double(count))));
  const int rows = (count + columns - 1) / columns;
  int cell_w = 0, cell_h = 0;
  for (const Image& im : images) {
    cell_w = std::max(cell_w, im.width);
    cell_h = std::max(cell_h, im.height);
  }
  const int pad = o.padding;
  const int label_band = has_labels ? o.font_size + pad : 0;
  const int title_size = o.font_size * 3 / 2;
  const int title_band = o.title.empty() ? 0 : title_size + 2 * pad;
  const long long width = static_cast<long long>(columns) * (cell_w + pad) + pad;
  const long long height =
      title_band + static_cast<long long>(rows) * (cell_h + label_band + pad) + pad;
  if (width > 65535 || height > 65535) {
    throw Error("contact sheet of " + std::to_string(width) + "x" + std::to_string(height) +
                " pixels is too large; use fewer or smaller images");
  }
  require_memory(
      static_cast<std::uint64_t>(width) * height * 3 * sizeof(float),
      "a contact sheet of " + std::to_string(width) + "x" + std::to_string(height) + " pixels",
      "use fewer or smaller images");
  if (!o.title.empty()) require_text_fits(o.title, "the title", font, title_size);
  for (std::size_t i = 0; i < o.labels.size(); ++i) {
    require_text_fits(o.labels[i], "label " + std::to_string(i + 1), font, o.font_size);
  }
  Image sheet(static_cast<int>(width), static_cast<int>(height), {"R", "G", "B"}, kBackground);

  if (!o.title.empty())
    draw_text(sheet, font, static_cast<int>(width / 2), pad, o.title, title_size);
  for (int i = 0; i < count; ++i) {
    const Image& im = images[i];
    int ir = im.channel_index("R"), ig = im.channel_index("G"), ib = im.channel_index("B");
    if (ir < 0 || ig < 0 || ib < 0) {
      if (im.channel_count() != 1) {
        throw Error("image " + std::to_string(i + 1) +
                    " of the contact sheet has no R, G, B channels and more than one channel");
      }
      ir = ig = ib = 0;
    }
    const int cx = pad + (i % columns) * (cell_w + pad);
    const int cy = title_band + pad + (i / columns) * (cell_h + label_band + pad);
    const int ox = cx + (cell_w - im.width) / 2, oy = cy + (cell_h - im.height) / 2;
    for (int y = 0; y < im.height; ++y) {
      for (int x = 0; x < im.width; ++x) {
        sheet.at(ox + x, oy + y, 0) = apply_tone_curve(im.at(x, y, ir), o.display);
        sheet.at(ox + x, oy + y, 1) = apply_tone_curve(im.at(x, y, ig), o.display);
        sheet.at(ox + x, oy + y, 2) = apply_tone_curve(im.at(x, y, ib), o.display);
      }
    }
    if (has_labels) {
      draw_text(sheet, font, cx + cell_w / 2, cy + cell_h + pad / 2, o.labels[i], o.font_size);
    }
    if (progress && !progress(double(i + 1) / count, "contact sheet")) throw Cancelled();
  }
  if (progress) progress(1.0, "contact sheet");
  return sheet;
}

}  // namespace drift::render
