// One source for marks' defaults and ranges: the table in
// terrain/marks/marks_parameters.toml. docs/marks.md's options table must agree
// with it row by row, and validate() must hold every range at both of its ends.
#include "terrain/marks/marks_parameters.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "terrain/marks/ground_material.h"
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

// docs/marks.md's two materials tables are the code's: the presets' numbers
// (material_preset) and each track-file key's range and meaning
// (material_parameters()), row by row, and nothing else.
TEST(MarksParameters, DocsMaterialsTablesAgreeWithThePresetsAndTheRows) {
  using drift::terrain::format_value;
  using drift::testing::markdown_table;
  const auto presets =
      markdown_table(DRIFT_SOURCE_DIR "/docs/marks.md", "| preset | theta (deg) | alpha | sigma |");
  std::size_t listed = 0;
  for (const std::string name : {"sand", "mud", "snow"}) {
    const Material m = *material_preset(name);
    const auto row = std::find_if(presets.begin(), presets.end(),
                                  [&](const auto& cells) { return cells.at(0) == name; });
    ASSERT_NE(row, presets.end()) << name << " is not in docs/marks.md's presets table";
    ++listed;
    EXPECT_EQ(row->at(1), format_value(m.theta_deg)) << name;
    EXPECT_EQ(row->at(2), format_value(m.alpha)) << name;
    EXPECT_EQ(row->at(3), format_value(m.sigma)) << name;
    EXPECT_EQ(row->at(4), format_value(m.heave)) << name;
  }
  EXPECT_EQ(presets.size(), listed) << "docs/marks.md lists other presets";

  const auto keys =
      markdown_table(DRIFT_SOURCE_DIR "/docs/marks.md", "| material key | range | meaning |");
  ASSERT_EQ(keys.size(), material_parameters().size()) << "docs/marks.md's material keys";
  for (const auto& p : material_parameters()) {
    const std::string label = std::string("`") + p.key + "`";
    const auto row = std::find_if(keys.begin(), keys.end(),
                                  [&](const auto& cells) { return cells.at(0) == label; });
    ASSERT_NE(row, keys.end()) << label << " is not in docs/marks.md's material keys";
    EXPECT_EQ(row->at(1), p.range()) << label;
    EXPECT_EQ(row->at(2), p.meaning) << label;
  }
}
