// The soil simulation's numeric parameters in one table, kept as data in
// soil_parameters.toml beside this header and compiled by scripts/parameter_table.cmake
// (terrain/parameter.h): each row names the SoilOptions field, the `drift soil` flag and the
// scenario file's key where there are any, the range, the unit and what it
// means. validate(SoilOptions), the scenario reader, the flags with their
// help, and docs/soil.md's options table come from it; the defaults are
// SoilOptions{}'s (dry sand's soil), and
// tests/soil/soil_parameters_test.cpp fails when docs/soil.md disagrees.
#pragma once

#include <vector>

#include "terrain/parameter.h"
#include "terrain/soil/soil_options.h"

namespace drift::soil {

using SoilParameter = terrain::Parameter<SoilOptions>;

// Every numeric parameter, in the order of docs/soil.md's table.
const std::vector<SoilParameter>& soil_parameters();

}  // namespace drift::soil
