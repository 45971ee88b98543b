// The snow-cover descriptor's parameters in one table, kept as data in
// cover_parameters.toml beside this header and compiled by scripts/parameter_table.cmake
// (terrain/parameter.h): each row names the CoverOptions field, the `drift snow cover` flag, the
// range, the unit and what it means. CoverOptions::validate(), the command
// line's flags and help, and docs/snow.md's options table come from it; the
// defaults are CoverOptions{}'s, and tests/snow/cover_parameters_test.cpp
// fails when docs/snow.md disagrees.
#pragma once

#include <vector>

#include "snow/cover_options.h"
#include "terrain/parameter.h"

namespace drift::snow {

using CoverParameter = terrain::Parameter<CoverOptions>;

// Every numeric parameter, in the order of docs/snow.md's table.
const std::vector<CoverParameter>& cover_parameters();

}  // namespace drift::snow
