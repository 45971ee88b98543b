// A stage's parameter table (terrain/parameter.h) as a subcommand's flags: one
// option per row that has a flag of its own, its help made from the row (what
// it means, its range, the default from Options{}), whole numbers checked as
// such. After parsing, apply() range-checks and sets the fields of the flags
// the user gave, and flag_names() maps every row's field to its flag so that
// validate_flags() can speak of flags. Adding a row adds the flag, its help,
// its check and its docs row (tested) at once.
#pragma once

#include <CLI/CLI.hpp>
#include <cstddef>
#include <string>
#include <vector>

#include "pipeline/cli.h"
#include "terrain/parameter.h"

namespace drift::pipeline {

template <class Options>
class ParameterFlags {
 public:
  using Table = std::vector<terrain::Parameter<Options>>;

  using HelpFn = std::string (*)(const terrain::Parameter<Options>&);

  // `help_of` makes a flag's help from its row; by default help() below (a
  // stage whose defaults depend on a mode, as dunes' on the model, gives its own).
  explicit ParameterFlags(const Table& table, HelpFn help_of = &ParameterFlags::help)
      : table_(table), help_of_(help_of), values_(table.size(), 0.0) {}

  // Adds one option per row with a flag of its own to `sub`.
  void add_to(CLI::App& sub) {
    for (std::size_t i = 0; i < table_.size(); ++i) {
      const terrain::Parameter<Options>& p = table_[i];
      if (!p.has_own_flag()) continue;
      CLI::Option* opt = sub.add_option(p.flag, values_[i], help_of_(p));
      if (p.integer) opt->check(CLI::Validator(whole_number, "WHOLE"));
    }
  }

  // Sets `o`'s field for each flag given on `sub`'s command line. A value
  // outside its row's range is a usage error naming the flag, raised here,
  // before it is converted to the field's type (a huge integer would not fit).
  void apply(const CLI::App& sub, Options& o) const {
    for (std::size_t i = 0; i < table_.size(); ++i) {
      const terrain::Parameter<Options>& p = table_[i];
      if (!p.has_own_flag() || !sub.count(p.flag)) continue;
      if (!p.admits(values_[i]))
        usage_error(std::string(p.flag) + " is " + terrain::refused_value(values_[i]) +
                    "; it must lie in " + p.range());
      p.set(o, values_[i]);
    }
  }

  // (field, flag) for every row the command line sets, for validate_flags().
  FlagNames flag_names() const {
    FlagNames names;
    for (const terrain::Parameter<Options>& p : table_)
      if (*p.flag) names.emplace_back(p.field, p.flag);
    return names;
  }

  // A flag's help: its meaning, range and default, from the row.
  static std::string help(const terrain::Parameter<Options>& p) {
    return std::string(p.meaning) + " " + p.range() +
           " (default: " + terrain::format_value(p.get(Options{})) + ")";
  }

 private:
  const Table& table_;
  HelpFn help_of_;
  std::vector<double> values_;
};

}  // namespace drift::pipeline
