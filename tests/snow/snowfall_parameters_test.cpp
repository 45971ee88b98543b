// One source for snowfall's defaults and ranges: the table in
// snow/snowfall_parameters.toml. docs/snowfall.md's options table must agree
// with it row by row, and validate() must hold every range at both ends.
#include "snow/snowfall_parameters.h"

#include <gtest/gtest.h>

#include "tests/parameter_table.h"

using namespace drift::snow;

DRIFT_PARAMETER_TABLE_TESTS(SnowfallParameters, snowfall_parameters, "docs/snowfall.md")

// No field or flag has two rows (the docs test finds rows by flag).
TEST(SnowfallParameters, EveryRowNamesAFieldOfItsOwn) {
  const auto& table = snowfall_parameters();
  for (std::size_t i = 0; i < table.size(); ++i)
    for (std::size_t j = i + 1; j < table.size(); ++j) {
      EXPECT_STRNE(table[i].field, table[j].field);
      if (*table[i].flag) {
        EXPECT_STRNE(table[i].flag, table[j].flag);
      }
    }
}
