// drift snow cover DEM.tif -o COVER.tif: the snow-cover descriptor of paper 001
// (Tangent Sphere Accessibility of the smoothed DEM, altitude, sun aspect),
// block by block (snow::snow_cover_to_files), so DEMs larger than memory.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>

#include "pipeline/cli.h"
#include "pipeline/parameter_flags.h"
#include "pipeline/progress_bar.h"
#include "snow/cover_parameters.h"
#include "snow/snow_cover.h"
#include "terrain/error.h"
#include "terrain/output_set.h"

namespace drift::pipeline {

namespace {

struct CoverCommand {
  std::string dem, output, accessibility, descriptor, hemisphere = "auto",
                                                      sun_step = "per-triangle";
  double snow_line = 0.0;
  int block = 0;
  // The table's flags (snow/cover_parameters.h); only those given override
  // CoverOptions{}'s defaults.
  ParameterFlags<snow::CoverOptions> parameters{snow::cover_parameters()};
};

void run_cover(CoverCommand& c, const CLI::App& sub) {
  snow::CoverOptions o;
  c.parameters.apply(sub, o);
  FlagNames flags = c.parameters.flag_names();
  if (sub.count("--radius") && sub.count("--radius-cells")) {
    usage_error("give --radius (metres) or --radius-cells, not both");
  }
  if (sub.count("--region") && sub.count("--region-cells")) {
    usage_error("give --region (the paper's 50 m cells) or --region-cells, not both");
  }
  o.sun_step = c.sun_step == "mean" ? snow::SunStep::Mean : snow::SunStep::PerTriangle;
  if (sub.count("--snow-line")) o.snow_line_m = c.snow_line;
  if (sub.count("--band") && !sub.count("--snow-line")) usage_error("--band needs --snow-line");
  o.hemisphere = c.hemisphere == "north"   ? snow::Hemisphere::North
                 : c.hemisphere == "south" ? snow::Hemisphere::South
                                           : snow::Hemisphere::Auto;
  // The ranges live in the table; checked before reading the DEM.
  flags.emplace_back("snow_line_m", "--snow-line");
  validate_flags([&o] { o.validate(); }, flags);
  OutputSet outputs({c.output, c.descriptor, c.accessibility}, {c.dem});
  snow::CoverFilesResult r;
  // Block by block: the cover is what the renderer's [snow] cover takes,
  // snow's share 1 - t.
  naming_input(c.dem, [&] {
    r = snow::snow_cover_to_files({c.dem, c.output, c.descriptor, c.accessibility, c.block}, o,
                                  terminal_progress("snow cover"));
  });
  outputs.commit();
  std::printf(
      "snow cover: %d x %d cells of %g m, region %d cells, probe radius %g m, mean cover %.3f, "
      "sun from the %s -> %s\n",
      r.width, r.height, r.cell_m, snow::region_in_cells(o, r.cell_m),
      snow::radius_in_metres(o, r.cell_m), r.mean_cover,
      r.southern ? "north (southern hemisphere)" : "south (northern hemisphere)", c.output.c_str());
}

}  // namespace

void snow_cover_flags(CLI::App* sub, CoverCommand* c) {
  sub->add_option("dem", c->dem, "DEM GeoTIFF in metres (drift import)")->required();
  sub->add_option("-o,--output", c->output, "snow cover GeoTIFF, 1 - t in [0, 1]")->required();
  c->parameters.add_to(*sub);
  add_choice(*sub, "--sun-step", c->sun_step, {"per-triangle", "mean"},
             "per-triangle (the paper: t = t phi + 1 - phi for each facing triangle) or mean "
             "(phi averaged over the 12 triangles, applied once)");
  sub->add_option("--snow-line", c->snow_line,
                  "snow line in metres: no snow below, full above (default: (z/zmax)^2)");
  add_choice(*sub, "--hemisphere", c->hemisphere, {"auto", "north", "south"},
             "where the sun stands: auto (from the DEM's CRS), north or south");
  sub->add_option("--descriptor", c->descriptor, "also write t (0 snow, 1 rock)");
  sub->add_option("--accessibility", c->accessibility, "also write the TSA in metres");
  sub->add_option("--block", c->block,
                  "cells a side of the blocks worked in (default: DRIFT_BLOCK_CELLS, else 4 halos "
                  "rounded up to 256, at least 2048, within half the memory; docs/snow.md)")
      ->check(CLI::Range(16, 1048576));
}

DRIFT_COMMAND(40, "cover",
              "snow-cover descriptor of a DEM (tangent sphere accessibility, "
              "altitude, sun aspect; paper 001)",
              snow_cover_flags, run_cover, "snow", "snow stages: cover (descriptor), fall");

}  // namespace drift::pipeline
