// The shape every subcommand shares: options parsed by CLI11, one action run
// after a successful parse, and the options every subcommand takes (--threads).
//
// Each subcommand lives in its own file, pipeline/cmd_<name>.cpp, which defines
// its flags and action and registers them as one row with DRIFT_COMMAND; the
// build picks up every cmd_*.cpp, so adding a subcommand touches no other file.
// The action only calls library code and reports. Library errors are
// drift::Error (exit 1); CLI11 parse errors and usage_error() exit 2.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
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

// Adds --halo N into `halo` (0 to 2^20 cells, its default shown): the cells
// around a --block that the block's window also works, for the stages that
// work block by block (marks, snow fall). `help` says what the halo holds.
CLI::Option* add_halo_option(CLI::App& sub, int& halo, const std::string& help);

// Runs `run`, naming `input` in any drift::Error it throws ("IN: what"), so
// a library's message says which file it was about; a cancel passes as is.
void naming_input(const std::string& input, const std::function<void()>& run);

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

// Adds option `name` taking one of `choices` into `value`, its help listing
// them and the default. Returns the option.
CLI::Option* add_choice(CLI::App& sub, const std::string& name, std::string& value,
                        const std::vector<std::string>& choices, const std::string& help);

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
// A subcommand as one row: its name and help, the function declaring its flags
// on its options struct, and its action, run once they are parsed with the
// struct (and, where it takes it, the subcommand, e.g. to ask whether a flag
// was given); under a group such as `drift snow`, the group's name and help
// (the first row of a group gives its help).
template <class Options>
struct Command {
  template <class Run>
  Command(const char* name, const char* help, void (*flags)(CLI::App* sub, Options* options),
          Run run, const char* group = "", const char* group_help = "")
      : name(name), help(help), flags(flags), group(group), group_help(group_help) {
    if constexpr (std::is_invocable_v<Run, Options&, const CLI::App&>)
      this->run = run;
    else
      this->run = [run](Options& o, const CLI::App&) { run(o); };
  }

  const char* name;
  const char* help;
  void (*flags)(CLI::App* sub, Options* options);
  std::function<void(Options&, const CLI::App&)> run;
  const char* group;
  const char* group_help;
};

// Adds `row`'s subcommand (with --threads, add_subcommand) under `root` or its
// group, its options struct living as long as the subcommand.
template <class Options>
void add_command(CLI::App& root, const Command<Options>& row) {
  CLI::App& parent = *row.group ? command_group(root, row.group, row.group_help) : root;
  auto options = std::make_shared<Options>();
  CLI::App* sub =
      add_subcommand(parent, row.name, row.help,
                     [options, run = row.run](const CLI::App& self) { run(*options, self); });
  row.flags(sub, options.get());
}

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

// Registers the subcommand of a pipeline/cmd_<name>.cpp at static-initialisation
// time: DRIFT_COMMAND(order, name, help, flags, run[, group, group help]), the
// arguments of a Command row. `order` sorts the help listing: 10 import,
// 20 info, 30 dunes, 40 snow, 50 marks, 60 soil, 65 mesh, 70 render, 80 merge,
// 90 compare, 100 sheet.
#define DRIFT_COMMAND(order, ...)                                                    \
  static const ::drift::pipeline::RegisterCommand drift_register_command {           \
    order, [](CLI::App& root) {                                                      \
      ::drift::pipeline::add_command(root, ::drift::pipeline::Command{__VA_ARGS__}); \
    }                                                                                \
  }
