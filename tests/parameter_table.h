// The checks every stage's parameter table (terrain/parameter.h) must pass:
// the docs' options table agrees with it row by row (default, range,
// meaning), and the options struct's validate() holds every range at both of
// its ends, rejects NaN and infinity, and names the field.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "terrain/parameter.h"
#include "tests/markdown_table.h"

namespace drift::testing {

// The rows of `page`'s table headed "| option | default | range | meaning |",
// by their first cell: default, range, meaning.
inline std::map<std::string, std::vector<std::string>> documented_options(const std::string& page) {
  std::map<std::string, std::vector<std::string>> rows;
  for (const auto& cells : markdown_table(page, "| option | default | range | meaning |"))
    if (cells.size() == 4 && cells[0].rfind('`', 0) == 0)
      rows[cells[0]] = {cells[1], cells[2], cells[3]};
  return rows;
}

// A row's first cell in the docs: its file key and its flag, each in
// backticks, "`[soil] phi` / `--phi`"; "" for a row with neither.
template <class Options>
std::string docs_label(const terrain::Parameter<Options>& p) {
  std::string label;
  if (*p.key) label = std::string("`") + p.key + "`";
  if (*p.key && *p.flag) label += " / ";
  if (*p.flag) label += std::string("`") + p.flag + "`";
  return label;
}

// Every row with a key or a flag is in `page`'s options table with the
// struct's default, the row's range and meaning; the table lists nothing else.
template <class Options>
void expect_docs_agree(const std::vector<terrain::Parameter<Options>>& table,
                       const std::string& page) {
  const auto rows = documented_options(page);
  const Options defaults;
  std::size_t documented = 0;
  for (const terrain::Parameter<Options>& p : table) {
    const std::string label = docs_label(p);
    if (label.empty()) continue;
    ++documented;
    const auto it = rows.find(label);
    if (it == rows.end()) {
      ADD_FAILURE() << label << " is not in " << page;
      continue;
    }
    EXPECT_EQ(it->second[0], terrain::format_value(p.get(defaults))) << label;
    EXPECT_EQ(it->second[1], p.range()) << label;
    EXPECT_EQ(it->second[2], p.meaning) << label;
  }
  EXPECT_EQ(rows.size(), documented) << page << " lists other options";
}

// validate() takes each range's ends (and the default) and refuses what lies
// just beyond them, NaN, infinity and, for integers, fractions, naming the
// field and the range.
template <class Options>
void expect_validate_holds_ranges(const std::vector<terrain::Parameter<Options>>& table) {
  EXPECT_NO_THROW(Options{}.validate());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const terrain::Parameter<Options>& p : table) {
    const double step = p.integer ? 1.0 : 1e-9 * std::max(1.0, std::fabs(p.lo));
    const double hi_step = p.integer ? 1.0 : 1e-9 * std::max(1.0, std::fabs(p.hi));
    std::vector<double> good = {terrain::low_open(p.ends) ? p.lo + step : p.lo};
    std::vector<double> bad = {terrain::low_open(p.ends) ? p.lo : p.lo - step, nan,
                               std::numeric_limits<double>::infinity()};
    if (std::isfinite(p.hi)) {
      good.push_back(terrain::high_open(p.ends) ? p.hi - hi_step : p.hi);
      bad.push_back(terrain::high_open(p.ends) ? p.hi : p.hi + hi_step);
    }
    if (p.integer) bad.push_back(p.lo + 0.5);
    for (const double v : good) {
      Options o;
      p.set(o, v);
      EXPECT_NO_THROW(o.validate()) << p.field << " = " << v;
    }
    for (const double v : bad) {
      if (p.integer && !std::isfinite(v)) continue;  // an int field cannot hold it
      Options o;
      p.set(o, v);
      if (p.integer && p.get(o) != v) continue;  // truncated on the way in
      try {
        o.validate();
        ADD_FAILURE() << p.field << " = " << v << " passed";
      } catch (const terrain::ParameterError& e) {
        EXPECT_EQ(e.field(), p.field);
        EXPECT_NE(std::string(e.what()).find(p.range()), std::string::npos) << e.what();
      }
    }
  }
}

}  // namespace drift::testing

// The two tests every parameter table gets: `suite`.DocsAgreeWithTheTable
// (against `page`, relative to the source tree) and
// `suite`.ValidateHoldsEveryRangeAndNamesTheField.
#define DRIFT_PARAMETER_TABLE_TESTS(suite, table, page)                    \
  TEST(suite, DocsAgreeWithTheTable) {                                     \
    drift::testing::expect_docs_agree(table(), DRIFT_SOURCE_DIR "/" page); \
  }                                                                        \
  TEST(suite, ValidateHoldsEveryRangeAndNamesTheField) {                   \
    drift::testing::expect_validate_holds_ranges(table());                 \
  }
