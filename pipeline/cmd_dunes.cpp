// drift dunes: wind ripples or dunes by Nishimori-Ouchi saltation and creep
// (paper 002) with avalanching, written as a float32 GeoTIFF height field in
// metres, tileable for every wind azimuth.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "dunes/sand_model.h"
#include "dunes/wind_frame.h"
#include "pipeline/cli.h"
#include "pipeline/progress_bar.h"
#include "terrain/output_set.h"
#include "terrain/raster_io.h"

namespace drift::pipeline {

namespace {

struct DunesCommand {
  std::string model = "ripples";
  std::string output;
  unsigned long long seed = 1;
  int snapshot_every = 0;
  dunes::SandOptions given;  // values as parsed; only those given override the defaults
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
  auto given = [&sub](const char* flag) { return sub.count(flag) > 0; };
  const dunes::SandOptions& g = c.given;
  if (given("--size")) o.size = g.size;
  if (given("--cell")) o.cell_m = g.cell_m;
  if (given("--height-unit")) o.height_unit = g.height_unit;
  if (given("--steps")) o.steps = g.steps;
  if (given("--wind")) o.wind_from_deg = g.wind_from_deg;
  if (given("--L0")) o.L0 = g.L0;
  if (given("--b")) o.b = g.b;
  if (given("--q")) o.q = g.q;
  if (given("--b-prime")) o.b_prime = g.b_prime;
  if (given("--creep")) o.creep = g.creep;
  if (given("--amplitude")) o.initial_amplitude = g.initial_amplitude;
  if (given("--repose")) o.repose_deg = g.repose_deg;
  if (given("--shadow")) o.shadow_deg = g.shadow_deg;
  if (given("--reattach")) o.reattach = g.reattach;
  o.seed = c.seed;
  dunes::validate(o);
  const double simulated_from = dunes::lattice_wind_from(o.wind_from_deg, o.size);
  if (std::fabs(simulated_from - o.wind_from_deg) > 1e-9) {
    std::fprintf(stderr,
                 "drift dunes: note: --wind %g runs as %.2f, the nearest direction of whole "
                 "columns and rows whose turned lattice tiles the %d-cell grid\n",
                 o.wind_from_deg, simulated_from, o.size);
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

void add_dunes_command(CLI::App& root) {
  auto c = std::make_shared<DunesCommand>();
  auto self = std::make_shared<CLI::App*>(nullptr);
  CLI::App* sub = add_subcommand(
      root, "dunes", "wind ripples or dunes by saltation, creep and avalanching (Nishimori-Ouchi)",
      [c, self] { run_dunes(*c, **self); });
  *self = sub;
  dunes::SandOptions& o = c->given;
  sub->footer(
      "Defaults (ripples | dunes): --cell 0.015 | 1 m, --height-unit 0.0025 | 0.25 m,\n"
      "--steps 500 | 3000, --L0 5 | 20, --b 2 | 1, --q 0.1 | 0.2, --b-prime - | 0.02,\n"
      "--creep 0.25, --amplitude 1 | 2, --shadow 0 | 15, --reattach - | 1.\n"
      "Ripples: L = L0 + b H (cells, H in height units); dunes: L = L0 - b tanh(dH/dx),\n"
      "q = q0 + b' tanh(dH/dx). Ripples form at about L0 + 1 cells; see docs/dunes.md.");
  sub->add_option("--model", c->model, "ripples or dunes")
      ->check(CLI::IsMember({"ripples", "dunes"}))
      ->capture_default_str();
  sub->add_option("-o,--output", c->output, "output GeoTIFF (heights in metres)")->required();
  sub->add_option("--size", o.size, "cells per side of the periodic square grid [8, 16384] (256)");
  sub->add_option("--cell", o.cell_m, "cell size in metres [1e-4, 1000]");
  sub->add_option("--height-unit", o.height_unit,
                  "metres per model height unit [1e-6, 1000]: sets the physical slopes");
  sub->add_option("--steps", o.steps, "time steps [0, 1e7]; 0 writes the seeded start");
  sub->add_option(
      "--wind", o.wind_from_deg,
      "where the wind comes FROM, degrees clockwise from north, as in weather "
      "reports (270: a west wind) [-360, 360]. Any azimuth; off the axes it is rounded to "
      "a direction of whole columns and rows so that the field always tiles (within 2 "
      "degrees on a 256-cell grid, 1 on 1024; the run prints it)");
  sub->add_option("--L0", o.L0, "base flight length in cells [0.5, 64]");
  sub->add_option("--b", o.b, "flight-length coefficient [0, 32]");
  sub->add_option("--q", o.q, "height lifted per cell and step (dunes: q0) [1e-4, 2]");
  sub->add_option("--b-prime", o.b_prime, "dunes: extra lift on windward slopes [0, q)");
  sub->add_option("--creep", o.creep, "creep (diffusion) coefficient D [0, 1]");
  sub->add_option("--amplitude", o.initial_amplitude, "random start amplitude, height units");
  sub->add_option("--repose", o.repose_deg, "angle of repose of dry sand, degrees (34)");
  sub->add_option("--shadow", o.shadow_deg,
                  "wind-shadow angle behind crests, degrees (ripples 0, dunes 15; 0 = none)");
  sub->add_option(
      "--reattach", o.reattach,
      "with a shadow: the lift past it recovers over this many times the shadow's "
      "length [0, 16] (dunes 1: gentle windward faces; 2+: separate crescents; 0: at once)");
  sub->add_option("--snapshot-every", c->snapshot_every,
                  "also write OUT_<step>.tif every K steps (for animations)")
      ->check(CLI::Range(1, 10000000));
  add_seed_option(*sub, c->seed);
}

DRIFT_COMMAND(30, add_dunes_command);

}  // namespace drift::pipeline
