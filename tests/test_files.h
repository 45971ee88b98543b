// Files for the tests that run drift on disk: a fresh folder per test case
// (inside the process's private TMPDIR, tests/test_main.cpp) and whole-file
// reads and writes.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace drift::testing {

// An empty folder `group`/<test case> under the temporary directory.
inline std::filesystem::path test_dir(const std::string& group) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / group /
                                  ::testing::UnitTest::GetInstance()->current_test_info()->name();
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// The file's bytes ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

inline void put(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

}  // namespace drift::testing
