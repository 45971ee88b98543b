// One source for the soil simulation's defaults and ranges: the table in
// terrain/soil/soil_parameters.cpp. docs/soil.md's options table must agree
// with it row by row, and validate() must hold every range at both ends.
#include "terrain/soil/soil_parameters.h"

#include <gtest/gtest.h>

#include "tests/parameter_table.h"

using namespace drift::soil;

DRIFT_PARAMETER_TABLE_TESTS(SoilParameters, soil_parameters, "docs/soil.md")

// Every preset of table 6 lies within the table's ranges.
TEST(SoilParameters, ThePresetsAreValid) {
  for (const std::string& name : soil_preset_names()) {
    SoilOptions o;
    o.soil = soil_preset(name);
    EXPECT_NO_THROW(o.validate()) << name;
  }
}
