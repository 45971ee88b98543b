// The sand model's parameters in one table, kept as data in
// sand_parameters.toml beside this header and compiled by scripts/parameter_table.cmake (Mitsuba's
// parameter tables are the model): each row names the SandOptions field, the `drift dunes` flag,
// the unit, the valid range and what it means, as every stage's table does. validate(), the command
// line's flags and help, and docs/dunes.md's table all come from it: the defaults are
// default_options(model)'s, and tests/dunes/sand_parameters_test.cpp fails
// when docs/dunes.md disagrees with the table.
#pragma once

#include <vector>

#include "dunes/sand_options.h"
#include "terrain/parameter.h"

namespace drift::dunes {

// Every parameter with a range, in the order of docs/dunes.md's table (rows
// of the stages' one parameter type, terrain/parameter.h).
const std::vector<terrain::Parameter<SandOptions>>& sand_parameters();

// Whether only the dune model reads the row's field (the ripple model has no
// default for it).
bool dunes_only(const terrain::Parameter<SandOptions>& p);

}  // namespace drift::dunes
