// One validation idiom for the options structs of the stages: each has a
// validate() that checks its fields with require_field(), which throws a
// ParameterError naming the field in the library's words ("region is 40; it
// must lie in [1, 32]"). The command line maps fields to its flags
// (pipeline/cli.h, validate_flags), so library messages never name a flag.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include "terrain/error.h"

namespace drift::terrain {

class ParameterError : public Error {
 public:
  // `field`: the options struct's field; `problem`: what is wrong with it,
  // phrased to follow the field's name.
  ParameterError(std::string field, const std::string& problem)
      : Error(field + " " + problem), field_(std::move(field)), problem_(problem) {}
  const std::string& field() const { return field_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string field_;
  std::string problem_;
};

// `value` formatted as the messages give it (%g).
inline std::string format_value(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", value);
  return buf;
}

// Throws ParameterError(field, "is VALUE; it must lie in RANGE") unless `ok`
// (write the check so that NaN fails it). `range` in words: "[1, 32]",
// "(0, 10] m".
inline void require_field(bool ok, const std::string& field, double value,
                          const std::string& range) {
  if (!ok) throw ParameterError(field, "is " + format_value(value) + "; it must lie in " + range);
}

// The closed range [lo, hi] (finite values only).
inline void require_in(const std::string& field, double value, double lo, double hi,
                       const char* unit = "") {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "[" + string.
  std::string range = "[";
  range += format_value(lo);
  range += ", ";
  range += format_value(hi);
  range += "]";
  if (*unit) (range += " ") += unit;
  require_field(std::isfinite(value) && value >= lo && value <= hi, field, value, range);
}

}  // namespace drift::terrain
