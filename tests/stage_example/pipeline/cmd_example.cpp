// drift example: the throw-away stage's subcommand (tests/stage_example).
#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "pipeline/cli.h"
#include "terrain/example/ridge.h"
#include "terrain/output_set.h"
#include "terrain/raster_io.h"

namespace drift::pipeline {

namespace {

struct ExampleCommand {
  std::string output;
  int size = 64;
};

void run_example(const ExampleCommand& c) {
  OutputSet outputs({c.output});
  terrain::write_geotiff(example::ridge(c.size, 10.0), c.output, {"ridge height (m)", "m"});
  outputs.commit();
}

void example_flags(CLI::App* sub, ExampleCommand* c) {
  sub->add_option("-o,--output", c->output, "output GeoTIFF")->required();
  whole_in_range(sub->add_option("--size", c->size, "cells per side"), 3, 4096);
}

}  // namespace

DRIFT_COMMAND(65, "example", "a ridge (the example stage)", example_flags, run_example);

}  // namespace drift::pipeline
