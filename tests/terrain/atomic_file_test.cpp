#include "terrain/atomic_file.h"

#include <gtest/gtest.h>

#include <fstream>

#include "terrain/error.h"

namespace fs = std::filesystem;

TEST(AtomicFile, UncommittedOutputLeavesNothing) {
  fs::path dir = fs::temp_directory_path() / "drift_tests_atomic";
  fs::create_directories(dir);
  const fs::path target = dir / "out.txt";
  fs::remove(target);
  fs::path temp;
  {
    drift::AtomicFile f(target);
    temp = f.temp_path();
    std::ofstream(temp) << "partial";
    EXPECT_EQ(temp.extension(), ".txt");
  }
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_FALSE(fs::exists(target));
}

TEST(AtomicFile, CommitReplacesTarget) {
  fs::path dir = fs::temp_directory_path() / "drift_tests_atomic";
  fs::create_directories(dir);
  const fs::path target = dir / "out2.txt";
  std::ofstream(target) << "old";
  {
    drift::AtomicFile f(target);
    std::ofstream(f.temp_path()) << "new";
    f.commit();
  }
  std::ifstream in(target);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "new");
}

TEST(AtomicFile, MissingDirectoryIsAnError) {
  EXPECT_THROW(drift::AtomicFile("/nonexistent_dir_xyz/out.tif"), drift::Error);
}
