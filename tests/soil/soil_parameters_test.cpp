// One source for the soil simulation's defaults and ranges: the table in
// terrain/soil/soil_parameters.toml. docs/soil.md's options table must agree
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

// A value just past a bound is shown with the digits that tell it from the
// bound, not rounded onto it ("is 20; it must lie in [0, 20]").
TEST(SoilParameters, ARefusedValueIsShownAsGiven) {
  SoilOptions o;
  o.soil.cohesion = 20.0000001;
  try {
    o.validate();
    ADD_FAILURE() << "cohesion 20.0000001 passed";
  } catch (const drift::terrain::ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("is 20.0000001;"), std::string::npos) << e.what();
  }
  EXPECT_EQ(drift::terrain::refused_value(40.0), "40");
  EXPECT_EQ(drift::terrain::refused_value(0.1), "0.1");
}
