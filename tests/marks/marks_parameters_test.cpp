// One source for marks' defaults and ranges: the table in
// terrain/marks/marks_parameters.cpp. docs/marks.md's options table must agree
// with it row by row, and validate() must hold every range at both of its ends.
#include "terrain/marks/marks_parameters.h"

#include <gtest/gtest.h>

#include <cmath>

#include "terrain/marks/material.h"
#include "tests/parameter_table.h"

using namespace drift::marks;

DRIFT_PARAMETER_TABLE_TESTS(MarksParameters, marks_parameters, "docs/marks.md")

// A material's ranges: one table (material_parameters()) that Material::validate
// and track files both read; each end holds as its row says, with the error
// type every stage raises.
TEST(MarksParameters, MaterialRangesHoldAtBothEndsWithTheStagesErrorType) {
  for (const auto& p : material_parameters()) {
    Material m = *material_preset("sand");
    p.set(m, p.hi);
    EXPECT_NO_THROW(m.validate("test")) << p.key;
    p.set(m, p.hi + 1e-9);
    EXPECT_THROW(m.validate("test"), drift::terrain::ParameterError) << p.key;
    p.set(m, p.lo);
    if (drift::terrain::low_open(p.ends))
      EXPECT_THROW(m.validate("test"), drift::terrain::ParameterError) << p.key;
    else
      EXPECT_NO_THROW(m.validate("test")) << p.key;
    p.set(m, std::nan(""));
    EXPECT_THROW(m.validate("test"), drift::terrain::ParameterError) << p.key;
  }
}
