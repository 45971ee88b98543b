// One validation idiom for the options structs of the stages: each has a
// validate() that checks its fields with require_field(), which throws a
// ParameterError naming the field in the library's words ("region is 40; it
// must lie in [1, 32]"). The command line maps fields to its flags
// (pipeline/cli.h, validate_flags), so library messages never name a flag.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// A refused value as messages give it: %g, or as many digits as it takes
// where %g would round it onto a bound ("20.0000001", not "20", beside
// "[0, 20]").
inline std::string refused_value(double value) {
  std::string text = format_value(value);
  // The fewest digits that read back as the value (at most 17 do).
  for (int digits = 7;
       digits <= 17 && std::isfinite(value) && std::strtod(text.c_str(), nullptr) != value;
       ++digits) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    text = buf;
  }
  return text;
}

// Throws ParameterError(field, "is VALUE; it must lie in RANGE") unless `ok`
// (write the check so that NaN fails it). `range` in words: "[1, 32]",
// "(0, 10] m".
inline void require_field(bool ok, const std::string& field, double value,
                          const std::string& range) {
  if (!ok) throw ParameterError(field, "is " + refused_value(value) + "; it must lie in " + range);
}

// Which ends of a range belong to it: [lo, hi], (lo, hi], [lo, hi) or (lo, hi).
enum class Ends { Closed, OpenLow, OpenHigh, Open };
inline bool low_open(Ends e) { return e == Ends::OpenLow || e == Ends::Open; }
inline bool high_open(Ends e) { return e == Ends::OpenHigh || e == Ends::Open; }

// A range as messages, help and docs give it: "[lo, hi]", "(lo, hi)" with open
// ends, "inf)" for an unbounded upper one, then the unit if any.
inline std::string range_text(double lo, double hi, Ends ends = Ends::Closed,
                              const char* unit = "") {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "[" + string.
  std::string range = low_open(ends) ? "(" : "[";
  range += format_value(lo);
  range += ", ";
  if (std::isinf(hi))
    range += "inf)";
  else
    (range += format_value(hi)) += high_open(ends) ? ")" : "]";
  if (*unit) (range += " ") += unit;
  return range;
}

// Whether `v` is finite and lies in the range (NaN fails every comparison).
inline bool in_range(double v, double lo, double hi, Ends ends) {
  return std::isfinite(v) && (low_open(ends) ? v > lo : v >= lo) &&
         (high_open(ends) ? v < hi : v <= hi);
}

// The closed range [lo, hi] (finite values only).
inline void require_in(const std::string& field, double value, double lo, double hi,
                       const char* unit = "") {
  require_field(std::isfinite(value) && value >= lo && value <= hi, field, value,
                range_text(lo, hi, Ends::Closed, unit));
}

// One row of an options struct's parameter table (Mitsuba's parameter tables
// are the model): the field as library errors name it, the command line's
// flag and the file's key, the range, the unit and what it means. The struct's validate(), the
// command line's flags and help (pipeline/parameter_flags.h), and the docs'
// table all come from the rows; the defaults are the struct's own (Options{}).
template <class Options>
struct Parameter {
  const char* field;
  // The command line's flag: "--maps"; a part of a flag that takes several
  // values: "--direction AZ"; "" for a field the command line does not set.
  const char* flag;
  double lo, hi;  // hi may be +inf (an integer field's hi must fit its type)
  Ends ends;
  bool integer;  // a whole number
  const char* unit;
  const char* meaning;
  double (*get)(const Options&);
  void (*set)(Options&, double);
  // The key in a scene or scenario file, with its table: "[soil] phi"; "" if none.
  const char* key = "";

  std::string range() const { return range_text(lo, hi, ends, unit); }
  // Finite, in range and, for an integer, whole.
  bool admits(double v) const {
    return in_range(v, lo, hi, ends) && (!integer || v == std::floor(v));
  }
  // A flag of its own (not "" and not a part of a flag with several values).
  bool has_own_flag() const {
    const std::string f = flag;
    return f.rfind("--", 0) == 0 && f.find(' ') == std::string::npos;
  }
  // Throws ParameterError naming the field unless `o`'s value is admitted.
  void require(const Options& o) const { require_field(admits(get(o)), field, get(o), range()); }
};

// A row's get and set for member `m` of an options struct (int or double).
#define DRIFT_PARAMETER_FIELD(Options, m)                    \
  [](const Options& o) { return static_cast<double>(o.m); }, \
      [](Options& o, double v) { o.m = static_cast<decltype(o.m)>(v); }

}  // namespace drift::terrain
