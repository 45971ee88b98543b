// main() of every test executable: each test process works in a private
// temporary directory. CTest runs each test case as its own process, and two
// suites may run at once (two worktrees, -j2), so fixed names under /tmp
// collided (Tiles.CommandLineTilesMergeToTheSingleRun failed when two suites
// ran together). Here TMPDIR is pointed at a fresh mkdtemp directory before any
// test starts, so std::filesystem::temp_directory_path() in the tests and the
// `drift` processes they start all land in it; it is removed at the end.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const char* base = std::getenv("TMPDIR");
  std::string dir = std::string(base && *base ? base : "/tmp") + "/drift-test-XXXXXX";
  if (mkdtemp(dir.data()) == nullptr) {
    std::perror(("cannot create a private test directory " + dir).c_str());
    return 1;
  }
  setenv("TMPDIR", dir.c_str(), 1);
  const int status = RUN_ALL_TESTS();
  std::error_code ignored;  // a test may leave files; they go with the directory
  std::filesystem::remove_all(dir, ignored);
  return status;
}
