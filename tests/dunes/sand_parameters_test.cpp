// One source for the sand model's defaults and ranges: the table in
// dunes/sand_parameters.cpp. docs/dunes.md's parameter table must agree with
// it row by row (flag, both defaults, range, unit, meaning), and validate()
// must hold every range at both of its ends.
#include "dunes/sand_parameters.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "terrain/parameter.h"

using namespace drift::dunes;
using drift::terrain::format_value;

namespace {

std::vector<std::string> cells_of(const std::string& row) {
  std::vector<std::string> out;
  std::stringstream in(row);
  std::string cell;
  std::getline(in, cell, '|');  // before the first bar
  while (std::getline(in, cell, '|')) {
    const auto a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
    out.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
  }
  if (!out.empty() && out.back().empty()) out.pop_back();
  return out;
}

// docs/dunes.md's rows by flag: ripples, dunes, range, unit, meaning.
std::map<std::string, std::vector<std::string>> documented() {
  std::ifstream f(DRIFT_SOURCE_DIR "/docs/dunes.md");
  std::map<std::string, std::vector<std::string>> rows;
  std::string line;
  bool in_table = false;
  while (std::getline(f, line)) {
    if (line.rfind("| option | ripples | dunes | range | unit | meaning |", 0) == 0)
      in_table = true;
    if (!in_table) continue;
    if (line.empty()) break;
    const auto cells = cells_of(line);
    if (cells.size() == 6 && cells[0].rfind("`--", 0) == 0)
      rows[cells[0].substr(1, cells[0].size() - 2)] = {cells[1], cells[2], cells[3], cells[4],
                                                       cells[5]};
  }
  return rows;
}

}  // namespace

TEST(SandParameters, DocsAgreeWithTheTable) {
  const auto rows = documented();
  const SandOptions ripples = default_options(Model::Ripples);
  const SandOptions dunes = default_options(Model::Dunes);
  ASSERT_EQ(rows.size(), sand_parameters().size()) << "docs/dunes.md lists other flags";
  for (const SandParameter& p : sand_parameters()) {
    const auto it = rows.find(p.flag);
    ASSERT_NE(it, rows.end()) << p.flag << " is not in docs/dunes.md";
    const std::vector<std::string>& d = it->second;
    EXPECT_EQ(d[0], p.dunes_only ? "-" : format_value(p.get(ripples))) << p.flag;
    EXPECT_EQ(d[1], format_value(p.get(dunes))) << p.flag;
    EXPECT_EQ(d[2], format_value(p.lo) + " - " + format_value(p.hi)) << p.flag;
    EXPECT_EQ(d[3], p.unit) << p.flag;
    EXPECT_EQ(d[4], p.meaning) << p.flag;
  }
}

TEST(SandParameters, ValidateHoldsEveryRangeAndNamesTheField) {
  for (const Model model : {Model::Ripples, Model::Dunes}) {
    for (const SandParameter& p : sand_parameters()) {
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
