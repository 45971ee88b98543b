#include "pipeline/cli.h"

#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <regex>

#include "terrain/error.h"
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
// job) is refused: taken as the option not given, the output it asks for would
// silently not be written and the input it names not read, with exit 0. Free
// text may be empty.
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

CLI::Option* add_choice(CLI::App& sub, const std::string& name, std::string& value,
                        const std::vector<std::string>& choices, const std::string& help) {
  return sub.add_option(name, value, help)->check(CLI::IsMember(choices))->capture_default_str();
}

CLI::App* add_subcommand(CLI::App& parent, const std::string& name, const std::string& description,
                         std::function<void()> run) {
  CLI::App* sub = parent.add_subcommand(name, description);
  auto threads = std::make_shared<int>(0);
  whole_in_range(sub->add_option("--threads", *threads,
                                 "worker threads (0 = all cores); results do not depend on it"),
                 0, 4096);
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

CLI::Option* add_halo_option(CLI::App& sub, int& halo, const std::string& help) {
  return sub.add_option("--halo", halo, help)->check(CLI::Range(0, 1 << 20))->capture_default_str();
}

void naming_input(const std::string& input, const std::function<void()>& run) {
  try {
    run();
  } catch (const Cancelled&) {
    throw;
  } catch (const Error& e) {
    throw Error(input + ": " + e.what());
  }
}

void add_seed_option(CLI::App& sub, unsigned long long& seed) {
  // CLI11 reads "-1", "2^64" and "1e23" all as 2^64 - 1 without a word: a seed
  // is the digits of a number below 2^64, nothing else.
  const auto seed_problem = [](const std::string& text) -> std::string {
    const std::string max = std::to_string(std::numeric_limits<unsigned long long>::max());
    if (!whole_number(text).empty()) return "must be a whole number 0.." + max;
    const std::string digits = text.substr(std::min(text.find_first_not_of('0'), text.size()));
    if (digits.size() > max.size() || (digits.size() == max.size() && digits > max)) {
      return "'" + text + "' is larger than " + max;
    }
    return {};
  };
  sub.add_option("--seed", seed, "random seed; the same seed gives the same bits")
      ->check(CLI::Validator(seed_problem, "SEED"))
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

CLI::Option* whole_in_range(CLI::Option* option, long long lo, long long hi) {
  // An optional leading minus for ranges that allow negative values.
  const auto whole = [lo](const std::string& text) {
    const bool negative = lo < 0 && !text.empty() && text[0] == '-';
    return whole_number(negative ? text.substr(1) : text);
  };
  return option->check(CLI::Validator(whole, "WHOLE"))->check(CLI::Range(lo, hi));
}

void usage_error(const std::string& message) { throw CLI::ValidationError(message); }

void refuse_files_among_frames(const std::string& flag, const std::string& dir,
                               const std::string& prefix, const std::string& ext,
                               const std::vector<std::filesystem::path>& named) {
  if (dir.empty()) return;
  std::error_code ec;
  const std::filesystem::path frames = std::filesystem::weakly_canonical(dir, ec);
  // The step's number has 5 digits or more (%05d); prefix and ext are ours.
  const std::regex frame_name(prefix + "[0-9]{5,}\\" + ext);
  const auto among = std::find_if(named.begin(), named.end(), [&](const auto& p) {
    if (p.empty()) return false;
    const std::filesystem::path file = std::filesystem::weakly_canonical(p, ec);
    return file.parent_path() == frames && std::regex_match(file.filename().string(), frame_name);
  });
  if (among == named.end()) return;
  std::string message = "'";
  message.append(among->string()).append("' is named like the frames ").append(flag);
  message.append(" '").append(dir).append("' writes (").append(prefix).append("NNNNN");
  message.append(ext).append(", one a frame), so one would overwrite the other; give it ");
  throw Error(message.append("another name or folder"));
}

std::vector<CommandRegistration>& command_registry() {
  static std::vector<CommandRegistration> registry;
  return registry;
}

}  // namespace drift::pipeline
