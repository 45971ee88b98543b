// drift info RASTER: what a raster holds, without changing it.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "pipeline/cli.h"
#include "terrain/import.h"
#include "terrain/raster_io.h"

namespace drift::pipeline {

namespace {

struct InfoOptions {
  std::string raster;
};

void run_info(const InfoOptions& o) {
  const terrain::RasterHeader header = terrain::read_raster_header(o.raster);
  const terrain::HeightField grid = terrain::read_raster(o.raster);
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  std::size_t invalid = 0;
  for (float v : grid.values()) {
    if (std::isnan(v)) {
      ++invalid;
      continue;
    }
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  std::printf("file:      %s\n", o.raster.c_str());
  std::printf("driver:    %s (%s, %d band%s)\n", header.driver.c_str(), header.data_type.c_str(),
              header.bands, header.bands == 1 ? "" : "s");
  std::printf("size:      %d x %d cells\n", header.width, header.height);
  std::string crs;
  const auto metres = terrain::cell_size_metres(header.geo, header.width, header.height, &crs);
  std::printf("crs:       %s\n", crs.c_str());
  std::printf("cell:      %.2f x %.2f m (east-west x north-south)\n", metres[0], metres[1]);
  if (invalid == grid.size()) {
    std::printf("heights:   all cells are nodata\n");
  } else {
    std::printf("heights:   %.2f .. %.2f\n", lo, hi);
  }
  std::printf("nodata:    %zu cells\n", invalid);
}

}  // namespace

void info_flags(CLI::App* sub, InfoOptions* o) {
  sub->add_option("raster", o->raster, "any raster GDAL reads")->required();
}

DRIFT_COMMAND(20, "info", "print a raster's size, CRS, cell size and heights", info_flags,
              run_info);

}  // namespace drift::pipeline
