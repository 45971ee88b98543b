// The shape every subcommand shares: options parsed by CLI11, one action run
// after a successful parse, and the options every subcommand takes (--threads).
//
// Each subcommand lives in its own file, pipeline/cmd_<name>.cpp, which defines
// `void add_<name>_command(CLI::App&)` and registers it with DRIFT_COMMAND; the
// build picks up every cmd_*.cpp, so adding a subcommand touches no other file.
// The action only calls library code and reports. Library errors are
// drift::Error (exit 1); CLI11 parse errors and usage_error() exit 2.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace drift::pipeline {

// Adds subcommand `name` to `parent` with --threads N, and arranges for `run` to be
// called (with TBB limited to N threads when N > 0) once its options are parsed.
CLI::App* add_subcommand(CLI::App& parent, const std::string& name, const std::string& description,
                         std::function<void()> run);
// The same for an action that reads its own App (e.g. to ask whether a flag
// was given): `run` receives the subcommand.
CLI::App* add_subcommand(CLI::App& parent, const std::string& name, const std::string& description,
                         std::function<void(const CLI::App&)> run);

// A group of subcommands such as `drift snow cover` / `drift snow fall`: returns
// the group `name` under `root`, creating it on first use.
CLI::App& command_group(CLI::App& root, const std::string& name, const std::string& description);

// Adds the standard --seed option (a 64-bit unsigned seed).
void add_seed_option(CLI::App& sub, unsigned long long& seed);

// The flags that set an options struct's fields, as (field, flag) pairs.
using FlagNames = std::vector<std::pair<std::string, std::string>>;

// Runs `validate` (an options struct's validate()) and turns a
// terrain::ParameterError about a field into one about its flag ("--region is
// 40; it must lie in [1, 32]"): a usage error (exit 2) if `usage`, else a
// drift::Error (exit 1). Fields without a flag keep the library's message.
void validate_flags(const std::function<void()>& validate, const FlagNames& flags,
                    bool usage = true);

// A CLI11 check for the integer rows of a parameter table: "" for a whole
// number (digits only), else the problem.
std::string whole_number(const std::string& text);

// Checks an integer option as a whole number first ("1e3" says "must be a whole
// number", not "not in range"), then within [lo, hi]. Returns `option`.
CLI::Option* whole_in_range(CLI::Option* option, long long lo, long long hi);

// Throws a usage error (exit 2) with `message`, e.g. for incompatible options.
[[noreturn]] void usage_error(const std::string& message);

// A sequence written one file a step into `dir` (the option `flag`, e.g.
// --frames) as PREFIX + digits + EXT: throws drift::Error (exit 1) if one of
// `named` (the run's inputs and other outputs) is such a file there, which a
// frame would write over or be written over by (both exited 0, one file lost).
void refuse_files_among_frames(const std::string& flag, const std::string& dir,
                               const std::string& prefix, const std::string& ext,
                               const std::vector<std::filesystem::path>& named);

// --- registry --------------------------------------------------------------
using CommandAdder = void (*)(CLI::App& root);

struct CommandRegistration {
  int order;  // position in `drift --help`
  CommandAdder add;
};

std::vector<CommandRegistration>& command_registry();

struct RegisterCommand {
  RegisterCommand(int order, CommandAdder add) { command_registry().push_back({order, add}); }
};

}  // namespace drift::pipeline

// Registers a subcommand adder at static-initialisation time. `order` sorts the
// help listing: 10 import, 20 info, 30 dunes, 40 snow, 50 marks, 60 soil,
// 70 render, 80 merge, 90 compare, 100 sheet.
#define DRIFT_COMMAND(order, adder) \
  static const ::drift::pipeline::RegisterCommand drift_register_##adder { order, adder }
