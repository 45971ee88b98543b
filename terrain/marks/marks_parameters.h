// Marks' numeric options in one table, kept as data in
// marks_parameters.toml beside this header and compiled by scripts/parameter_table.cmake
// (terrain/parameter.h): each row names the MarksOptions field, the `drift marks` flag or the track
// file's key, the range, the unit and what it means. MarksOptions::validate(), the command line's
// flags and help, and docs/marks.md's options table come from it; the defaults are
// MarksOptions{}'s, and tests/marks/marks_parameters_test.cpp fails when docs/marks.md disagrees.
#pragma once

#include <vector>

#include "terrain/marks/marks_options.h"
#include "terrain/parameter.h"

namespace drift::marks {

using MarksParameter = terrain::Parameter<MarksOptions>;

// Every numeric parameter, in the order of docs/marks.md's table.
const std::vector<MarksParameter>& marks_parameters();

}  // namespace drift::marks
