// drift import DEM -o OUT.tif: any raster GDAL reads -> float32 GeoTIFF in
// metres (UTM of its centre), nodata filled, optionally cropped and resampled;
// block by block (terrain::import_dem_to_file), so rasters larger than memory.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <memory>

#include "pipeline/cli.h"
#include "pipeline/progress_bar.h"
#include "terrain/import.h"
#include "terrain/output_set.h"
#include "terrain/raster_io.h"

namespace drift::pipeline {

namespace {

struct ImportCommand {
  std::string input, output;
  std::vector<double> crop, crop_lonlat;
  double resample = std::nan("");  // none: the source's cell size
  terrain::ImportOptions options;
};

void run_import(const ImportCommand& c) {
  terrain::ImportOptions o = c.options;
  if (!c.crop.empty()) o.crop = std::array<double, 4>{c.crop[0], c.crop[1], c.crop[2], c.crop[3]};
  if (!c.crop_lonlat.empty()) {
    o.crop_lonlat = std::array<double, 4>{c.crop_lonlat[0], c.crop_lonlat[1], c.crop_lonlat[2],
                                          c.crop_lonlat[3]};
  }
  if (!std::isnan(c.resample)) o.resample_m = c.resample;
  validate_flags([&o] { o.validate(); },
                 {{"crop", "--crop"},
                  {"crop_lonlat", "--crop-lonlat"},
                  {"resample_m", "--resample"},
                  {"exaggeration", "--exaggerate"},
                  {"block", "--block"}},
                 false);
  OutputSet outputs({c.output}, {c.input});
  const terrain::ImportFileResult r =
      terrain::import_dem_to_file(c.input, c.output, o, terminal_progress("import"));
  outputs.commit();
  for (const auto& line : r.report) std::printf("import: %s\n", line.c_str());
  std::printf("import: wrote %s\n", c.output.c_str());
}

}  // namespace

void import_flags(CLI::App* sub, ImportCommand* c) {
  sub->add_option("dem", c->input, "input raster (GeoTIFF, .hgt, DTED, ASCII grid, USGS DEM, ...)")
      ->required();
  sub->add_option("-o,--output", c->output, "output GeoTIFF")->required();
  auto* crop = sub->add_option("--crop", c->crop, "xmin,ymin,xmax,ymax in the DEM's own CRS")
                   ->expected(4)
                   ->delimiter(',');
  sub->add_option("--crop-lonlat", c->crop_lonlat, "west,south,east,north in degrees (WGS 84)")
      ->expected(4)
      ->delimiter(',')
      ->excludes(crop);
  sub->add_option("--resample", c->resample, "output cell size in metres");
  sub->add_flag("--keep-crs", c->options.keep_crs, "keep a geographic CRS (cells stay degrees)");
  sub->add_option("--exaggerate", c->options.exaggeration, "vertical exaggeration (0, 100]");
  sub->add_option("--block", c->options.block,
                  "cells a side of the blocks worked in (default: DRIFT_BLOCK_CELLS, else 2048)");
}

DRIFT_COMMAND(10, "import", "any DEM GDAL reads -> float32 GeoTIFF in metres (UTM), nodata filled",
              import_flags, run_import);

}  // namespace drift::pipeline
