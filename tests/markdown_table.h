// Reading a table of a Markdown page in the docs, for the tests that hold the
// docs to the code's parameter tables (one reader for all of them).
#pragma once

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace drift::testing {

// The cells of one table row, trimmed: "| a | b |" -> {"a", "b"}.
inline std::vector<std::string> markdown_cells(const std::string& row) {
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

// The rows (as cells) of the table of `page` whose header line starts with
// `header`, up to the blank line that ends it; the header and the rule
// beneath it are left out. Empty if the page has no such table.
inline std::vector<std::vector<std::string>> markdown_table(const std::string& page,
                                                            const std::string& header) {
  std::ifstream f(page);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  bool in_table = false;
  while (std::getline(f, line)) {
    if (!in_table) {
      in_table = line.rfind(header, 0) == 0;
      continue;
    }
    if (line.empty() || line[0] != '|') break;
    if (line.find("---") != std::string::npos &&
        line.find_first_not_of("|-: ") == std::string::npos)
      continue;
    rows.push_back(markdown_cells(line));
  }
  return rows;
}

}  // namespace drift::testing
