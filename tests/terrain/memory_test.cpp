// DRIFT_MEMORY_LIMIT is read strictly: the documented forms and nothing else
// ("1T" had read as 1 byte, "8 G" as 8 bytes, and "abc", "0", "-5", "nan" as no
// cap, with no word naming the variable).
#include "terrain/memory.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "terrain/error.h"

namespace {

using drift::parse_byte_size;

constexpr std::uint64_t kKiB = 1024, kMiB = kKiB * 1024, kGiB = kMiB * 1024, kTiB = kGiB * 1024;

TEST(Memory, ByteSizesInEveryDocumentedForm) {
  EXPECT_EQ(parse_byte_size("4096"), 4096u);
  EXPECT_EQ(parse_byte_size("4096B"), 4096u);
  EXPECT_EQ(parse_byte_size("64K"), 64 * kKiB);
  EXPECT_EQ(parse_byte_size("64k"), 64 * kKiB);
  EXPECT_EQ(parse_byte_size("512M"), 512 * kMiB);
  EXPECT_EQ(parse_byte_size("512MiB"), 512 * kMiB);
  EXPECT_EQ(parse_byte_size("512MB"), 512 * kMiB);
  EXPECT_EQ(parse_byte_size("8G"), 8 * kGiB);
  EXPECT_EQ(parse_byte_size("8GiB"), 8 * kGiB);
  EXPECT_EQ(parse_byte_size("1T"), kTiB);
  EXPECT_EQ(parse_byte_size("1TiB"), kTiB);
  EXPECT_EQ(parse_byte_size("1.5G"), 3 * kGiB / 2);
  EXPECT_EQ(parse_byte_size("0.5K"), 512u);
}

TEST(Memory, AnythingElseIsNotASize) {
  for (const char* bad : {"",    "abc", "0",     "0G",  "-5",  "-5G",    "+5G",      "nan",
                          "inf", "1e3", "0x10",  "8 G", " 8G", "8G ",    "1X",       "1GiBs",
                          "1iB", "..5", "1..5G", ".",   "G",   "16384P", "99999999T"}) {
    EXPECT_FALSE(parse_byte_size(bad).has_value()) << "'" << bad << "'";
  }
}

TEST(Memory, MalformedLimitIsRefusedNamingTheVariable) {
  setenv("DRIFT_MEMORY_LIMIT", "8 G", 1);
  const std::string problem = drift::memory_limit_problem();
  EXPECT_NE(problem.find("DRIFT_MEMORY_LIMIT is '8 G'"), std::string::npos) << problem;
  // A library caller gets the same refusal rather than a run without a cap.
  EXPECT_THROW(drift::available_memory_bytes(), drift::Error);
  setenv("DRIFT_MEMORY_LIMIT", "1T", 1);
  EXPECT_EQ(drift::memory_limit_problem(), "");
  EXPECT_LE(drift::available_memory_bytes(), kTiB);
  setenv("DRIFT_MEMORY_LIMIT", "64M", 1);
  EXPECT_EQ(drift::available_memory_bytes(), 64 * kMiB);
  unsetenv("DRIFT_MEMORY_LIMIT");
  EXPECT_EQ(drift::memory_limit_problem(), "");
}

}  // namespace
