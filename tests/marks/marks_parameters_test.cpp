// One source for marks' defaults and ranges: the table in
// terrain/marks/marks_parameters.cpp. docs/marks.md's options table must agree
// with it row by row, and validate() must hold every range at both of its ends.
#include "terrain/marks/marks_parameters.h"

#include <gtest/gtest.h>

#include "tests/parameter_table.h"

using namespace drift::marks;

DRIFT_PARAMETER_TABLE_TESTS(MarksParameters, marks_parameters, "docs/marks.md")
