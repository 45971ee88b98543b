// The sand model's parameters in one table (Mitsuba's parameter tables are
// the model): each row names the SandOptions field, the `drift dunes` flag,
// the unit, the valid range and what it means. validate(), the command line's
// flags and help, and docs/dunes.md's table all come from it: the defaults are
// default_options(model)'s, and tests/dunes/sand_parameters_test.cpp fails
// when docs/dunes.md disagrees with the table.
#pragma once

#include <string>
#include <vector>

#include "dunes/sand_model.h"

namespace drift::dunes {

struct SandParameter {
  const char* field;  // the SandOptions member, as library errors name it
  const char* flag;   // the `drift dunes` flag
  double lo, hi;      // valid range, closed
  bool integer;       // a whole number
  bool dunes_only;    // read by the dune model only
  const char* unit;   // "" for none
  const char* meaning;
  double (*get)(const SandOptions&);
  void (*set)(SandOptions&, double);
};

// Every parameter with a range, in the order of docs/dunes.md's table.
const std::vector<SandParameter>& sand_parameters();

// "[lo, hi]" with the unit, as messages, help and docs give a range.
std::string range_text(const SandParameter& p);

}  // namespace drift::dunes
