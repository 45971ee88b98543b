// One source for the snow-cover descriptor's defaults and ranges: the table in
// snow/cover_parameters.toml. docs/snow.md's options table must agree with it
// row by row, and validate() must hold every range at both of its ends.
#include "snow/cover_parameters.h"

#include <gtest/gtest.h>

#include <limits>

#include "tests/parameter_table.h"

using namespace drift::snow;

DRIFT_PARAMETER_TABLE_TESTS(CoverParameters, cover_parameters, "docs/snow.md")

TEST(CoverParameters, ASnowLineMustBeFinite) {
  CoverOptions o;
  o.snow_line_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(o.validate(), drift::terrain::ParameterError);
  o.snow_line_m = 2400.0;
  EXPECT_NO_THROW(o.validate());
}
