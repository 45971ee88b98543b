// Snowfall's parameters in one table, kept as data in
// snowfall_parameters.toml beside this header and compiled by scripts/parameter_table.cmake
// (terrain/parameter.h): each row names the SnowfallOptions field, the `drift snow fall` flag (or
// none: a field only the library sets), the range, the unit and what it means.
// SnowfallOptions::validate(), the command line's flags and help, and
// docs/snowfall.md's options table come from it; the defaults are
// SnowfallOptions{}'s, and tests/snow/snowfall_parameters_test.cpp fails when
// docs/snowfall.md disagrees.
#pragma once

#include <vector>

#include "snow/snowfall_options.h"
#include "terrain/parameter.h"

namespace drift::snow {

using SnowfallParameter = terrain::Parameter<SnowfallOptions>;

// Every numeric parameter: first those with a flag, in the order of
// docs/snowfall.md's table, then the library's own.
const std::vector<SnowfallParameter>& snowfall_parameters();

}  // namespace drift::snow
