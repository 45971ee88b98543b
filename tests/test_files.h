// Files for the tests that run drift on disk: a fresh folder per test case
// (inside the process's private TMPDIR, tests/test_main.cpp), whole-file
// reads and writes, and running the drift binary.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
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

// The folder test_dir(group) of the running test case, made empty on the
// case's first call only, so helpers can name files in it without passing it.
inline std::filesystem::path case_dir(const std::string& group) {
  static std::string test;
  static std::filesystem::path folder;
  const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  if (name != test) test = name, folder = test_dir(group);
  return folder;
}

// The file's bytes ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

inline void put(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// Runs the drift binary (DRIFT_EXECUTABLE) with `args` (shell words), its
// output and errors into `dir`/log.txt (read by drift_log). Returns the exit
// status, or 128 + the signal that ended it.
inline int run_drift(const std::string& args, const std::filesystem::path& dir) {
  const std::string cmd =
      std::string(DRIFT_EXECUTABLE) + " " + args + " > " + (dir / "log.txt").string() + " 2>&1";
  const int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
}

// What the last run_drift in `dir` printed.
inline std::string drift_log(const std::filesystem::path& dir) { return slurp(dir / "log.txt"); }

}  // namespace drift::testing
