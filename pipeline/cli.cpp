#include "pipeline/cli.h"

#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <memory>

#include "terrain/parameter.h"

namespace drift::pipeline {

CLI::App* add_subcommand(CLI::App& parent, const std::string& name, const std::string& description,
                         std::function<void()> run) {
  CLI::App* sub = parent.add_subcommand(name, description);
  auto threads = std::make_shared<int>(0);
  sub->add_option("--threads", *threads,
                  "worker threads (0 = all cores); results do not depend on it")
      ->check(CLI::Range(0, 4096));
  sub->callback([threads, run = std::move(run)] {
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

void usage_error(const std::string& message) { throw CLI::ValidationError(message); }

std::vector<CommandRegistration>& command_registry() {
  static std::vector<CommandRegistration> registry;
  return registry;
}

}  // namespace drift::pipeline
