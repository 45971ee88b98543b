// One source for the snow-cover descriptor's defaults and ranges: the table in
// snow/cover_parameters.cpp. docs/snow.md's options table must agree with it
// row by row, and validate() must hold every range at both of its ends.
#include "snow/cover_parameters.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "tests/markdown_table.h"

using namespace drift::snow;
using drift::terrain::format_value;

namespace {

// docs/snow.md's rows by flag: default, range, meaning.
std::map<std::string, std::vector<std::string>> documented() {
  std::map<std::string, std::vector<std::string>> rows;
  for (const auto& cells : drift::testing::markdown_table(DRIFT_SOURCE_DIR "/docs/snow.md",
                                                          "| option | default | range | meaning |"))
    if (cells.size() == 4 && cells[0].rfind("`--", 0) == 0)
      rows[cells[0].substr(1, cells[0].size() - 2)] = {cells[1], cells[2], cells[3]};
  return rows;
}

}  // namespace

TEST(CoverParameters, DocsAgreeWithTheTable) {
  const auto rows = documented();
  const CoverOptions defaults;
  ASSERT_EQ(rows.size(), cover_parameters().size()) << "docs/snow.md lists other options";
  for (const CoverParameter& p : cover_parameters()) {
    const auto it = rows.find(p.flag);
    ASSERT_NE(it, rows.end()) << p.flag << " is not in docs/snow.md";
    EXPECT_EQ(it->second[0], format_value(p.get(defaults))) << p.flag;
    EXPECT_EQ(it->second[1], p.range()) << p.flag;
    EXPECT_EQ(it->second[2], p.meaning) << p.flag;
  }
}

TEST(CoverParameters, ValidateHoldsEveryRangeAndNamesTheField) {
  EXPECT_NO_THROW(CoverOptions{}.validate());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const CoverParameter& p : cover_parameters()) {
    const double step = p.integer ? 1.0 : 1e-9 * std::max(1.0, std::fabs(p.lo));
    std::vector<double> good = {p.lo_open ? p.lo + step : p.lo};
    std::vector<double> bad = {p.lo_open ? p.lo : p.lo - step, nan,
                               std::numeric_limits<double>::infinity()};
    if (std::isfinite(p.hi)) {
      good.push_back(p.hi);
      bad.push_back(p.hi + (p.integer ? 1.0 : 1e-9 * std::max(1.0, p.hi)));
    }
    if (p.integer) bad.push_back(p.lo + 0.5);
    for (const double v : good) {
      CoverOptions o;
      p.set(o, v);
      EXPECT_NO_THROW(o.validate()) << p.field << " = " << v;
    }
    for (const double v : bad) {
      if (p.integer && !std::isfinite(v)) continue;  // an int field cannot hold it
      CoverOptions o;
      p.set(o, v);
      if (p.integer && p.get(o) != v) continue;  // truncated on the way in
      try {
        o.validate();
        ADD_FAILURE() << p.field << " = " << v << " passed";
      } catch (const drift::terrain::ParameterError& e) {
        EXPECT_EQ(e.field(), p.field);
        EXPECT_NE(std::string(e.what()).find(p.range()), std::string::npos) << e.what();
      }
    }
  }
}

TEST(CoverParameters, ASnowLineMustBeFinite) {
  CoverOptions o;
  o.snow_line_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(o.validate(), drift::terrain::ParameterError);
  o.snow_line_m = 2400.0;
  EXPECT_NO_THROW(o.validate());
}
