// drift sheet IMG... -o SHEET.png: a labelled grid of images (render/contact_sheet.h).
#include <CLI/CLI.hpp>
#include <memory>

#include "pipeline/cli.h"
#include "pipeline/progress_bar.h"
#include "render/contact_sheet.h"
#include "render/image_io.h"
#include "terrain/output_set.h"

namespace drift::pipeline {

namespace {

struct SheetCommandOptions {
  std::vector<std::string> images;
  std::string labels, title, output, font, tone = "clamp";
  int columns = 0, font_size = 14, padding = 8;
  double exposure = 0.0;
};

void run_sheet(const SheetCommandOptions& o) {
  render::ContactSheetOptions options;
  options.columns = o.columns;
  options.title = o.title;
  options.font_size = o.font_size;
  options.padding = o.padding;
  options.font = o.font;
  options.display.exposure_ev = o.exposure;
  options.display.curve = o.tone == "filmic" ? render::ToneCurve::Filmic : render::ToneCurve::Clamp;
  if (!o.labels.empty()) {
    std::string rest = o.labels;
    for (std::size_t pos; (pos = rest.find('|')) != std::string::npos; rest.erase(0, pos + 1)) {
      options.labels.push_back(rest.substr(0, pos));
    }
    options.labels.push_back(rest);
    if (options.labels.size() != o.images.size()) {
      usage_error("--labels has " + std::to_string(options.labels.size()) + " entries for " +
                  std::to_string(o.images.size()) + " images; separate one label per image by '|'");
    }
  }
  if (o.columns > static_cast<int>(o.images.size())) {
    usage_error("--columns " + std::to_string(o.columns) + " is more than the " +
                std::to_string(o.images.size()) + " images");
  }
  std::vector<std::filesystem::path> inputs(o.images.begin(), o.images.end());
  inputs.emplace_back(o.font);
  OutputSet outputs({o.output}, inputs);
  std::vector<render::Image> images;
  for (const auto& path : o.images) images.push_back(render::read_image(path));
  const render::Image sheet = render::contact_sheet(images, options, terminal_progress("sheet"));
  render::write_image(sheet, o.output, render::DisplayTransform{0.0, render::ToneCurve::Clamp});
  outputs.commit();
}

}  // namespace

void sheet_flags(CLI::App* sub, SheetCommandOptions* o) {
  sub->add_option("images", o->images, "images (EXR or PNG)")->required();
  sub->add_option("-o,--output", o->output, "output sheet (.png or .exr)")->required();
  sub->add_option("--labels", o->labels, "one label per image, separated by '|'");
  sub->add_option("--columns", o->columns, "images per row (default: about square)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--title", o->title, "title above the grid");
  whole_in_range(sub->add_option("--font-size", o->font_size, "label size in pixels, 6..128"), 6,
                 128)
      ->capture_default_str();
  whole_in_range(sub->add_option("--padding", o->padding, "pixels between cells, 0..256"), 0, 256)
      ->capture_default_str();
  sub->add_option("--font", o->font, "TrueType font file (default DejaVu Sans)");
  add_choice(*sub, "--tone", o->tone, {"clamp", "filmic"},
             "tone curve for linear EXR inputs: clamp | filmic");
  sub->add_option("--exposure", o->exposure, "exposure in EV applied to every image")
      ->check(CLI::Range(-64.0, 64.0))
      ->capture_default_str();
}

DRIFT_COMMAND(100, "sheet", "lay images out in a labelled grid (contact sheet)", sheet_flags,
              run_sheet);

}  // namespace drift::pipeline
