// drift dunes: wind ripples or dunes by Nishimori-Ouchi saltation and creep
// (paper 002) with avalanching, written as a float32 GeoTIFF height field in
// metres, tileable for every wind azimuth.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "dunes/sand_model.h"
#include "dunes/sand_parameters.h"
#include "dunes/wind_frame.h"
#include "pipeline/cli.h"
#include "pipeline/parameter_flags.h"
#include "pipeline/progress_bar.h"
#include "terrain/memory.h"
#include "terrain/output_set.h"
#include "terrain/parameter.h"
#include "terrain/raster_io.h"

namespace drift::pipeline {

namespace {

// A flag's help: its meaning, range and both models' defaults, from the table.
std::string parameter_help(const terrain::Parameter<dunes::SandOptions>& p) {
  const auto ripples = dunes::default_options(dunes::Model::Ripples);
  const auto dunes_defaults = dunes::default_options(dunes::Model::Dunes);
  return std::string(p.meaning) + " " + p.range() + " (default: ripples " +
         (dunes::dunes_only(p) ? std::string("-") : terrain::format_value(p.get(ripples))) +
         ", dunes " + terrain::format_value(p.get(dunes_defaults)) + ")";
}

struct DunesCommand {
  std::string model = "ripples";
  std::string output;
  unsigned long long seed = 1;
  int snapshot_every = 0;
  // The table's flags (dunes/sand_parameters.h); only those given override
  // the model's defaults.
  ParameterFlags<dunes::SandOptions> parameters{dunes::sand_parameters(), &parameter_help};
};

// OUT.tif -> OUT_00040.tif
std::filesystem::path snapshot_path(const std::filesystem::path& out, int step) {
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, "_%05d", step);
  return out.parent_path() / (out.stem().string() + suffix + out.extension().string());
}

void run_dunes(const DunesCommand& c, const CLI::App& sub) {
  const dunes::Model model = c.model == "dunes" ? dunes::Model::Dunes : dunes::Model::Ripples;
  dunes::SandOptions o = dunes::default_options(model);
  c.parameters.apply(sub, o);
  o.seed = c.seed;
  validate_flags([&o] { dunes::validate(o); }, c.parameters.flag_names());
  const double simulated_from = dunes::lattice_wind_from(o.wind_from_deg, o.size);
  if (std::fabs(simulated_from - o.wind_from_deg) > 1e-9) {
    std::fprintf(stderr,
                 "drift dunes: note: --wind %g runs as %.2f, the nearest direction of whole "
                 "columns and rows whose turned lattice tiles the %d-cell grid\n",
                 o.wind_from_deg, simulated_from, o.size);
  }
  if (c.snapshot_every > 0) {
    // A snapshot is turned to the grid (through a copy) beside the running
    // fields: 8 bytes a cell over validate's 12 (measured 18 in all).
    const std::uint64_t cells = static_cast<std::uint64_t>(o.size) * o.size;
    require_memory(cells * (12 + 8), "the sand grid and its snapshots",
                   "choose a smaller size, or fewer snapshots");
  }
  const std::filesystem::path out = c.output;
  // Snapshots are each complete when written (they come one by one); the field
  // itself is replaced only at the end.
  OutputSet outputs({out});
  const std::string description = c.model + " height (m)";
  auto snapshot = [&](int step, const terrain::HeightField& field) {
    terrain::write_geotiff(dunes::to_ground(field, o), snapshot_path(out, step),
                           {description, "m"});
  };
  const terrain::HeightField model_field =
      dunes::run(o, terminal_progress(c.model), c.snapshot_every, snapshot);
  terrain::write_geotiff(dunes::to_ground(model_field, o), out, {description, "m"});
  outputs.commit();
  std::printf("%s: %d x %d cells of %g m, %d steps, wind from %g deg -> %s\n", c.model.c_str(),
              o.size, o.size, o.cell_m, o.steps, o.wind_from_deg, c.output.c_str());
}

}  // namespace

void dunes_flags(CLI::App* sub, DunesCommand* c) {
  sub->footer(
      "Ripples: L = L0 + b H (cells, H in height units); dunes: L = L0 - b tanh(dH/dx),\n"
      "q = q0 + b' tanh(dH/dx). Ripples form at about L0 + 1 cells. Any wind azimuth; off\n"
      "the axes it is rounded to a direction of whole columns and rows so that the field\n"
      "always tiles (within 2 degrees on a 256-cell grid, 1 on 1024; the run prints it).\n"
      "See docs/dunes.md.");
  add_choice(*sub, "--model", c->model, {"ripples", "dunes"}, "ripples or dunes");
  sub->add_option("-o,--output", c->output, "output GeoTIFF (heights in metres)")->required();
  c->parameters.add_to(*sub);
  whole_in_range(sub->add_option("--snapshot-every", c->snapshot_every,
                                 "also write OUT_<step>.tif every K steps (for animations)"),
                 1, 10000000);
  add_seed_option(*sub, c->seed);
}

DRIFT_COMMAND(30, "dunes",
              "wind ripples or dunes by saltation, creep and avalanching (Nishimori-Ouchi)",
              dunes_flags, run_dunes);

}  // namespace drift::pipeline
