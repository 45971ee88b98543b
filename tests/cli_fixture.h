// What the CLI tests share beyond tests/test_files.h: a flat ground written
// as their input, and a run's result for the tests that drive drift
// themselves (a timeout, an environment, a signal at a chosen point).
#pragma once

#include <filesystem>
#include <string>

#include "terrain/raster_io.h"
#include "tests/dem_fixture.h"

namespace drift::testing {

// flat_utm_ground written as `dir`/ground.tif.
inline std::filesystem::path write_flat_utm_ground(const std::filesystem::path& dir, int n, float z,
                                                   double cell) {
  terrain::write_geotiff(flat_utm_ground(n, z, cell), dir / "ground.tif");
  return dir / "ground.tif";
}

struct RunResult {
  int status = -1;  // exit status, or 128 + signal
  std::string log;  // stdout and stderr
};

}  // namespace drift::testing
