// drift: the Driftscape command line. Parses, runs one subcommand, and turns
// failures into "drift: error: ..." with exit status 1 (2 for usage errors).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "pipeline/cli.h"
#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/temp_registry.h"

namespace {

// DRIFT_MEMORY_REPORT=1: the run's memory estimate on stderr at exit (any
// status), for the tests that hold it to the measured peak (docs/testing.md).
void report_memory_estimate() {
  const char* flag = std::getenv("DRIFT_MEMORY_REPORT");
  if (!flag || !*flag || std::string(flag) == "0") return;
  std::fprintf(stderr, "drift: memory estimate: %llu bytes (%s)\n",
               static_cast<unsigned long long>(drift::memory_estimate_bytes()),
               drift::memory_estimate_what().c_str());
}

}  // namespace

int main(int argc, char** argv) try {
  // SIGINT, SIGTERM, SIGHUP and every other signal that would end the process
  // from outside: remove temporary files, exit 128 + the signal (temp_registry.h).
  drift::install_signal_cleanup();
  std::atexit(report_memory_estimate);
  // A malformed DRIFT_MEMORY_LIMIT is refused before any work, as a usage error.
  if (const std::string problem = drift::memory_limit_problem(); !problem.empty()) {
    std::fprintf(stderr, "drift: usage error: %s\n", problem.c_str());
    return 2;
  }
  CLI::App app{"Driftscape: natural ground from real elevation data, rendered.", "drift"};
  app.set_version_flag("--version", "drift 0.1.0");
  app.require_subcommand(1);
  app.fallthrough(false);

  auto registry = drift::pipeline::command_registry();
  std::stable_sort(registry.begin(), registry.end(),
                   [](const auto& a, const auto& b) { return a.order < b.order; });
  for (const auto& command : registry) command.add(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --help-all, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "drift: usage error: %s\nRun with --help for the options.\n", e.what());
    return 2;
  } catch (const drift::Cancelled&) {
    std::fprintf(stderr, "drift: cancelled; no output written\n");
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "drift: error: out of memory; use a smaller input or size\n");
    return 1;
  } catch (const std::exception& e) {  // drift::Error (bad input) and anything else
    std::fprintf(stderr, "drift: error: %s\n", e.what());
    return 1;
  }
  return 0;
} catch (const std::exception& e) {
  // Anything escaping the handlers above (e.g. from building the command table).
  std::fprintf(stderr, "drift: error: %s\n", e.what());
  return 1;
}
