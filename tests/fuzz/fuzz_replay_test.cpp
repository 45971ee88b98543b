// Replays every fuzz target's seed corpus (tests/fuzz/corpus/<target>/) and
// regression inputs (tests/fuzz/regressions/<target>/, the files that once
// crashed or hung a reader): each must be read or refused with drift::Error.
// Under the sanitizer build (scripts/sanitize.sh) this is also where memory
// errors in the readers would show.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "tests/fuzz/fuzz_targets.h"

namespace fs = std::filesystem;

namespace {

std::vector<char> bytes_of(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(f), {});
}

class FuzzReplay : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzReplay, EveryKeptInputIsReadOrRefused) {
  setenv("DRIFT_MEMORY_LIMIT", "2G", 1);  // as under scripts/fuzz.sh
  int replayed = 0;
  for (const char* kind : {"corpus", "regressions"}) {
    const fs::path dir = fs::path(DRIFT_SOURCE_DIR) / "tests" / "fuzz" / kind / GetParam();
    if (!fs::is_directory(dir)) continue;
    for (const auto& entry : fs::directory_iterator(dir)) {
      const std::vector<char> data = bytes_of(entry.path());
      SCOPED_TRACE(entry.path().string());
      const auto start = std::chrono::steady_clock::now();
      EXPECT_NO_THROW(drift::fuzz::run_target(
          GetParam(), reinterpret_cast<const std::uint8_t*>(data.data()), data.size()));
      // A hang is a finding too: 20 s is far above any kept input's time (under
      // a second, a few under the sanitizers).
      EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                20.0);
      ++replayed;
    }
  }
  EXPECT_GT(replayed, 0) << "no seed or regression input for target " << GetParam();
}

std::vector<std::string> target_names() {
  std::vector<std::string> names;
  for (const auto& t : drift::fuzz::targets()) names.emplace_back(t.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(Fuzz, FuzzReplay, ::testing::ValuesIn(target_names()),
                         [](const auto& info) { return info.param; });

}  // namespace
