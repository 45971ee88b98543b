// Replays every fuzz target's seed corpus (tests/fuzz/corpus/<target>/) and
// regression inputs (tests/fuzz/regressions/<target>/, the files that once
// crashed or hung a reader): each must be read or refused with drift::Error.
// One test per input, so a hang is caught by that test's CTest TIMEOUT
// (tests/fuzz/CMakeLists.txt) and names the input; no clock is read here.
// Under the sanitizer build (scripts/sanitize.sh) this is also where memory
// errors in the readers would show.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "tests/fuzz/fuzz_targets.h"

namespace fs = std::filesystem;

namespace {

struct KeptInput {
  std::string target;
  fs::path file;
};

std::vector<char> bytes_of(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(f), {});
}

std::vector<KeptInput> kept_inputs() {
  std::vector<KeptInput> inputs;
  for (const auto& t : drift::fuzz::targets()) {
    for (const char* kind : {"corpus", "regressions"}) {
      const fs::path dir = fs::path(DRIFT_SOURCE_DIR) / "tests" / "fuzz" / kind / t.name;
      if (!fs::is_directory(dir)) continue;
      std::vector<fs::path> files;
      for (const auto& entry : fs::directory_iterator(dir)) files.push_back(entry.path());
      std::sort(files.begin(), files.end());  // stable test names and order
      for (const fs::path& f : files) inputs.push_back({t.name, f});
    }
  }
  return inputs;
}

// target_kind_file, with what gtest does not allow in a name as '_'.
std::string test_name(const KeptInput& in) {
  std::string name = in.target + "_" + in.file.parent_path().parent_path().filename().string() +
                     "_" + in.file.filename().string();
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

class FuzzReplay : public ::testing::TestWithParam<KeptInput> {};

TEST_P(FuzzReplay, IsReadOrRefused) {
  setenv("DRIFT_MEMORY_LIMIT", "2G", 1);  // as under scripts/fuzz.sh
  const std::vector<char> data = bytes_of(GetParam().file);
  SCOPED_TRACE(GetParam().file.string());
  EXPECT_NO_THROW(drift::fuzz::run_target(
      GetParam().target, reinterpret_cast<const std::uint8_t*>(data.data()), data.size()));
}

INSTANTIATE_TEST_SUITE_P(Fuzz, FuzzReplay, ::testing::ValuesIn(kept_inputs()),
                         [](const auto& info) { return test_name(info.param); });

// Every target keeps at least one input, so each reader is replayed.
TEST(FuzzReplayInputs, EveryTargetHasASeedOrRegressionInput) {
  const std::vector<KeptInput> inputs = kept_inputs();
  for (const auto& t : drift::fuzz::targets()) {
    const bool any = std::any_of(inputs.begin(), inputs.end(),
                                 [&](const KeptInput& in) { return in.target == t.name; });
    EXPECT_TRUE(any) << "no seed or regression input for target " << t.name;
  }
}

}  // namespace
