#include "pipeline/cli.h"

#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <memory>

#include "terrain/parameter.h"

namespace drift::pipeline {

namespace {

// CLI11's range checks compare with < and >, which NaN passes: every number a
// user gives must be finite, whatever its option's own range (exit 2).
void require_finite_numbers(const CLI::App& sub) {
  for (const CLI::Option* option : sub.get_options()) {
    if (option->get_type_name().find("FLOAT") == std::string::npos) continue;
    for (const std::string& given : option->results()) {
      char* end = nullptr;
      const double v = std::strtod(given.c_str(), &end);
      if (end != given.c_str() && !std::isfinite(v)) {
        usage_error(option->get_name() + " " + given + ": not a finite number; give a number");
      }
    }
  }
}

// An empty value (`--cover ""`, say from an unset shell variable in a batch
// job) was taken as the option not given: the output it asked for was not
// written, the input it named not read, with exit 0. Free text may be empty.
void require_nonempty_values(const CLI::App& sub) {
  for (const CLI::Option* option : sub.get_options()) {
    const std::string name = option->get_name();
    if (name == "--title" || name == "--labels") continue;  // drift sheet's free text
    for (const std::string& given : option->results()) {
      if (!given.empty()) continue;
      usage_error(option->nonpositional() ? name + " is empty; give a value or leave the option out"
                                          : "the " + name + " argument is empty; give a value");
    }
  }
}

}  // namespace

CLI::App* add_subcommand(CLI::App& parent, const std::string& name, const std::string& description,
                         std::function<void()> run) {
  CLI::App* sub = parent.add_subcommand(name, description);
  auto threads = std::make_shared<int>(0);
  sub->add_option("--threads", *threads,
                  "worker threads (0 = all cores); results do not depend on it")
      ->check(CLI::Range(0, 4096));
  sub->callback([sub, threads, run = std::move(run)] {
    require_finite_numbers(*sub);
    require_nonempty_values(*sub);
    std::unique_ptr<tbb::global_control> limit;
    if (*threads > 0) {
      limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(*threads));
    }
    run();
  });
  return sub;
}

CLI::App* add_subcommand(CLI::App& parent, const std::string& name, const std::string& description,
                         std::function<void(const CLI::App&)> run) {
  // The App exists only once add_subcommand returns: the action finds it
  // through a slot filled in afterwards.
  auto self = std::make_shared<CLI::App*>(nullptr);
  CLI::App* sub =
      add_subcommand(parent, name, description, [self, run = std::move(run)] { run(**self); });
  *self = sub;
  return sub;
}

CLI::App& command_group(CLI::App& root, const std::string& name, const std::string& description) {
  for (CLI::App* existing : root.get_subcommands({})) {
    if (existing->get_name() == name) return *existing;
  }
  CLI::App* group = root.add_subcommand(name, description);
  group->require_subcommand(1);
  return *group;
}

void add_seed_option(CLI::App& sub, unsigned long long& seed) {
  sub.add_option("--seed", seed, "random seed; the same seed gives the same bits")
      ->capture_default_str();
}

void validate_flags(const std::function<void()>& validate, const FlagNames& flags, bool usage) {
  try {
    validate();
  } catch (const terrain::ParameterError& e) {
    for (const auto& [field, flag] : flags) {
      if (field != e.field()) continue;
      const std::string message = flag + " " + e.problem();
      if (usage) usage_error(message);
      throw Error(message);
    }
    if (usage) usage_error(e.what());
    throw;
  }
}

std::string whole_number(const std::string& text) {
  return !text.empty() && text.find_first_not_of("0123456789") == std::string::npos
             ? std::string()
             : std::string("must be a whole number");
}

void usage_error(const std::string& message) { throw CLI::ValidationError(message); }

std::vector<CommandRegistration>& command_registry() {
  static std::vector<CommandRegistration> registry;
  return registry;
}

}  // namespace drift::pipeline
