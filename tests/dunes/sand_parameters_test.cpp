// One source for the sand model's defaults and ranges: the table in
// dunes/sand_parameters.toml. docs/dunes.md's parameter table must agree with
// it row by row (flag, both defaults, range, unit, meaning), and validate()
// must hold every range at both of its ends.
#include "dunes/sand_parameters.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "dunes/sand_model.h"
#include "terrain/parameter.h"
#include "tests/markdown_table.h"

using namespace drift::dunes;
using drift::terrain::format_value;

namespace {

// docs/dunes.md's rows by flag: ripples, dunes, range, unit, meaning.
std::map<std::string, std::vector<std::string>> documented() {
  std::map<std::string, std::vector<std::string>> rows;
  for (const auto& cells :
       drift::testing::markdown_table(DRIFT_SOURCE_DIR "/docs/dunes.md",
                                      "| option | ripples | dunes | range | unit | meaning |"))
    if (cells.size() == 6 && cells[0].rfind("`--", 0) == 0)
      rows[cells[0].substr(1, cells[0].size() - 2)] = {cells[1], cells[2], cells[3], cells[4],
                                                       cells[5]};
  return rows;
}

}  // namespace

TEST(SandParameters, DocsAgreeWithTheTable) {
  const auto rows = documented();
  const SandOptions ripples = default_options(Model::Ripples);
  const SandOptions dunes = default_options(Model::Dunes);
  ASSERT_EQ(rows.size(), sand_parameters().size()) << "docs/dunes.md lists other flags";
  for (const drift::terrain::Parameter<SandOptions>& p : sand_parameters()) {
    const auto it = rows.find(p.flag);
    ASSERT_NE(it, rows.end()) << p.flag << " is not in docs/dunes.md";
    const std::vector<std::string>& d = it->second;
    EXPECT_EQ(d[0], dunes_only(p) ? "-" : format_value(p.get(ripples))) << p.flag;
    EXPECT_EQ(d[1], format_value(p.get(dunes))) << p.flag;
    EXPECT_EQ(d[2], format_value(p.lo) + " - " + format_value(p.hi)) << p.flag;
    EXPECT_EQ(d[3], p.unit) << p.flag;
    EXPECT_EQ(d[4], p.meaning) << p.flag;
  }
}

TEST(SandParameters, ValidateHoldsEveryRangeAndNamesTheField) {
  for (const Model model : {Model::Ripples, Model::Dunes}) {
    for (const drift::terrain::Parameter<SandOptions>& p : sand_parameters()) {
      SandOptions o = default_options(model);
      EXPECT_NO_THROW(validate(o));
      if (p.field == std::string("b_prime") && model == Model::Dunes) continue;  // below q
      if (p.field == std::string("L0") && model == Model::Dunes) continue;       // above b
      for (const double bad : {p.lo - 1, p.hi * 2 + 1}) {
        p.set(o, bad);
        try {
          validate(o);
          ADD_FAILURE() << p.field << " = " << bad << " passed";
        } catch (const drift::terrain::ParameterError& e) {
          EXPECT_EQ(e.field(), p.field);
          EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
        }
      }
    }
  }
}
