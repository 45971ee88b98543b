#include "terrain/atomic_file.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "terrain/error.h"
#include "terrain/output_set.h"

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

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "drift_tests_atomic" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST(AtomicFile, TemporaryNameIsPrivateHiddenAndWithinTheNameLimit) {
  const fs::path d = fresh_dir("names");
  for (std::size_t length : {5u, 240u, 250u, 255u}) {
    const fs::path target = d / (std::string(length - 4, 'a') + ".tif");
    drift::AtomicFile f(target);
    const fs::path temp = f.temp_path();
    EXPECT_EQ(temp.parent_path(), d);
    EXPECT_EQ(temp.filename().string()[0], '.');
    EXPECT_LE(temp.filename().string().size(), 255u) << length;
    EXPECT_EQ(temp.extension(), ".tif") << length;
    EXPECT_EQ(fs::status(temp).permissions() & fs::perms::all, fs::perms(0600));
    std::ofstream(temp) << "x";
    f.commit();
    EXPECT_TRUE(fs::exists(target));
  }
}

TEST(AtomicFile, KeepsAnExistingFilesPermissions) {
  const fs::path d = fresh_dir("perms"), target = d / "out.txt";
  std::ofstream(target) << "old";
  fs::permissions(target, fs::perms(0604));
  drift::AtomicFile f(target);
  std::ofstream(f.temp_path()) << "new";
  f.commit();
  EXPECT_EQ(fs::status(target).permissions() & fs::perms::all, fs::perms(0604));
}

TEST(AtomicFile, RefusesLinksDevicesAndDirectories) {
  const fs::path d = fresh_dir("refuse");
  std::ofstream(d / "real.txt") << "keep";
  fs::create_symlink(d / "real.txt", d / "link.txt");
  EXPECT_THROW(drift::AtomicFile(d / "link.txt"), drift::Error);
  EXPECT_THROW(drift::AtomicFile("/dev/null"), drift::Error);
  EXPECT_THROW(drift::AtomicFile{d}, drift::Error);
  EXPECT_THROW(drift::AtomicFile(d / std::string(256, 'n')), drift::Error);
  EXPECT_EQ(read_all(d / "real.txt"), "keep");
}

namespace {

// Writes `text` to a and b as one output set (each an atomic file), committed.
void write_set(const fs::path& a, const fs::path& b, const std::string& text) {
  drift::OutputSet set({a, b});
  for (const fs::path& p : {a, b}) {
    drift::AtomicFile f(p);
    std::ofstream(f.temp_path()) << text;
    f.commit();
  }
  set.commit();
}

}  // namespace

TEST(OutputSet, ReplacesNothingUnlessEveryOutputIsWritten) {
  const fs::path d = fresh_dir("set"), a = d / "a.txt", b = d / "b.txt";
  std::ofstream(a) << "old a";
  {
    drift::OutputSet set({a, b});
    drift::AtomicFile fa(a);
    std::ofstream(fa.temp_path()) << "new a";
    fa.commit();
    EXPECT_EQ(read_all(a), "old a");           // not before the set commits
    EXPECT_THROW(set.commit(), drift::Error);  // b was never written
  }
  EXPECT_EQ(read_all(a), "old a");
  EXPECT_FALSE(fs::exists(b));
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 1);
  { write_set(a, b, "new"); }
  EXPECT_EQ(read_all(a), "new");
  EXPECT_EQ(read_all(b), "new");
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 2);
}

// Two runs writing the same outputs at once leave one run's set, never a mix
// (issue 34, class 7): a set replaces its outputs under an exclusive lock on
// their folder. Here the test holds that lock; a child process's set, written
// and committing, must wait for it and replace nothing meanwhile.
TEST(OutputSet, RunsWritingOneFolderReplaceTheirOutputsOneSetAtATime) {
  const fs::path d = fresh_dir("locked"), a = d / "a.txt", b = d / "b.txt";
  const int folder = open(d.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  ASSERT_GE(folder, 0);
  ASSERT_EQ(flock(folder, LOCK_EX), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      write_set(a, b, "child");
      _exit(0);
    } catch (...) {
      _exit(1);
    }
  }
  // Both temporary files written: the child is at its commit.
  const auto entries = [&] {
    return std::distance(fs::directory_iterator(d), fs::directory_iterator());
  };
  for (int i = 0; i < 1000 && entries() < 2; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_FALSE(fs::exists(a));
  EXPECT_FALSE(fs::exists(b));
  ASSERT_EQ(flock(folder, LOCK_UN), 0);
  close(folder);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_EQ(read_all(a), "child");
  EXPECT_EQ(read_all(b), "child");
}

TEST(OutputSet, RefusesInputsAndTwiceNamedOutputsBeforeCreatingAnything) {
  const fs::path d = fresh_dir("set_refuse"), in = d / "in.txt";
  std::ofstream(in) << "input";
  EXPECT_THROW(drift::OutputSet({d / "x.txt", d / "./x.txt"}), drift::Error);
  EXPECT_THROW(drift::OutputSet({d / "y.txt", d / "in.txt"}, {in}), drift::Error);
  fs::create_hard_link(in, d / "hard.txt");
  EXPECT_THROW(drift::OutputSet({d / "hard.txt"}, {in}), drift::Error);
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 2);
  EXPECT_EQ(read_all(in), "input");
}
