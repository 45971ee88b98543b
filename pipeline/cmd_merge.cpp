// drift merge TILE.exr... -o FRAME.exr|png: join the bands of `drift render
// --tile i/n` into the frame a single run gives, bit for bit.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "pipeline/cli.h"
#include "render/image_io.h"
#include "render/tiles.h"
#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/output_set.h"

namespace drift::pipeline {

namespace {

struct MergeOptions {
  std::vector<std::string> tiles;
  std::vector<std::string> outputs;
  double exposure = 0.0;
};

// An exposure the tiles recorded, in EV; a tile edited by hand or damaged gets a
// clear error rather than std::stod's.
double recorded_ev(const render::Image& frame, const char* name) {
  const std::string& text = *frame.attribute(name);
  char* end = nullptr;
  const double ev = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || !std::isfinite(ev) || std::fabs(ev) > 64) {
    throw Error("the tiles record an " + std::string(name) + " of '" + text +
                "', not a number in [-64, 64] EV; give --exposure EV");
  }
  return ev;
}

// The display settings the tiles were rendered with, unless overridden.
render::DisplayTransform display_of(const render::Image& frame, const CLI::App& sub,
                                    double exposure) {
  render::DisplayTransform d;
  if (const std::string* e = frame.attribute("exposure")) {
    // "auto": the merged frame is metered (render/auto_exposure.h).
    d.auto_exposure = *e == "auto";
    d.exposure_ev = d.auto_exposure ? 0.0 : recorded_ev(frame, "exposure");
  }
  if (const std::string* c = frame.attribute("exposure_compensation"); c && d.auto_exposure)
    d.exposure_ev = recorded_ev(frame, "exposure_compensation");
  if (const std::string* t = frame.attribute("tone"); t && *t == "clamp")
    d.curve = render::ToneCurve::Clamp;
  if (const std::string* w = frame.attribute("white_balance"); w && *w == "daylight")
    d.white_balance = render::kDaylightWhiteBalance;
  if (sub.count("--exposure")) d.exposure_ev = exposure, d.auto_exposure = false;
  return d;
}

void run_merge(const MergeOptions& o, const CLI::App& sub) {
  std::vector<std::filesystem::path> names(o.tiles.begin(), o.tiles.end());
  OutputSet outputs({o.outputs.begin(), o.outputs.end()}, names);
  std::vector<render::Image> tiles;
  tiles.reserve(names.size());
  for (const auto& t : names) tiles.push_back(render::read_image(t));
  // The tiles stay beside the merged frame until it is whole: merge_tiles
  // counts the frame, this counts both (the frame alone was half the peak).
  std::uint64_t held = 0;
  for (const render::Image& t : tiles) held += t.pixels.size() * sizeof(float);
  const render::Image& first = tiles.at(0);  // at least one: the option is required
  require_memory(held + static_cast<std::uint64_t>(std::max(0, first.frame.full_width)) *
                            static_cast<std::uint64_t>(std::max(0, first.frame.full_height)) *
                            first.channels.size() * sizeof(float),
                 "the " + std::to_string(tiles.size()) + " tiles and their merged frame",
                 "merge fewer channels or a smaller frame");
  const render::Image frame = render::merge_tiles(tiles, names);
  tiles.clear();
  const render::DisplayTransform display = display_of(frame, sub, o.exposure);
  for (const auto& f : o.outputs) render::write_image(frame, f, display);
  outputs.commit();
  std::printf("merged %zu tiles into %dx%d -> ", names.size(), frame.width, frame.height);
  for (const auto& f : o.outputs) std::printf("%s ", f.c_str());
  std::printf("\n");
}

}  // namespace

void merge_flags(CLI::App* sub, MergeOptions* o) {
  sub->add_option("tiles", o->tiles, "tile EXR files, in any order")->required();
  sub->add_option("-o,--output", o->outputs, "output file(s), .exr and/or .png")->required();
  sub->add_option("--exposure", o->exposure, "PNG exposure in EV (default: the render's)")
      ->check(CLI::Range(-20.0, 20.0));
}

DRIFT_COMMAND(80, "merge", "join tiles of drift render --tile i/n into the whole frame",
              merge_flags, run_merge);

}  // namespace drift::pipeline
