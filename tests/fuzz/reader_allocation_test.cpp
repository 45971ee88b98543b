// The largest single allocation a hostile input makes while drift reads it.
// This executable replaces the global operator new (drift, libstdc++,
// OpenImageIO and OpenEXR's C++ library allocate through it) to record the
// largest request and to refuse any over 1 GiB with std::bad_alloc, so a test
// fails, quickly and without touching the memory, if a small file makes a
// reader reserve gigabytes even when the read is refused in the end.
// OpenEXRCore allocates with malloc: its header parse is bounded by
// render/exr_header.cpp, and fuzz.sh's -malloc_limit_mb sees malloc too.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>

#include "render/image_io.h"
#include "terrain/error.h"
#include "terrain/mesh_io.h"

namespace {
std::atomic<std::size_t> g_largest{0};
}  // namespace

void* operator new(std::size_t bytes) {
  std::size_t seen = g_largest.load(std::memory_order_relaxed);
  while (bytes > seen && !g_largest.compare_exchange_weak(seen, bytes)) {
  }
  if (bytes > (std::size_t{1} << 30)) throw std::bad_alloc();
  if (void* p = std::malloc(bytes ? bytes : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t bytes) { return operator new(bytes); }
// Every operator new above allocates with malloc, so free is the matching
// release; GCC 12's -Wmismatched-new-delete cannot see that through inlining.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kBound = 64u << 20;  // what fuzz.sh's -malloc_limit_mb allows

fs::path regression(const std::string& target, const std::string& name) {
  return fs::path(DRIFT_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / target / name;
}

// Reads `file` with `read`, expecting drift::Error; returns its message and
// the largest single allocation made meanwhile (std::bad_alloc is a failure).
template <typename Read>
std::string refusal(const fs::path& file, std::size_t& largest, Read read) {
  g_largest = 0;
  std::string message;
  try {
    read(file);
    ADD_FAILURE() << file << " was read";
  } catch (const drift::Error& e) {
    message = e.what();
  } catch (const std::bad_alloc&) {
    ADD_FAILURE() << file << ": an allocation over 1 GiB was attempted";
  }
  largest = g_largest;
  return message;
}

std::string image_refusal(const fs::path& file, std::size_t& largest) {
  return refusal(file, largest, [](const fs::path& f) { drift::render::read_image(f); });
}

// The regression EXR `name` is refused naming the file and `reason`, having
// asked for no more than kBound bytes at once.
void expect_exr_refused_within_bound(const std::string& name, const std::string& reason) {
  const fs::path file = regression("image", name);
  std::size_t largest = 0;
  const std::string m = image_refusal(file, largest);
  EXPECT_LT(largest, kBound) << m;
  EXPECT_NE(m.find(file.string()), std::string::npos) << m;
  EXPECT_NE(m.find(reason), std::string::npos) << m;
}

// An "int" attribute declaring 24 bytes: OpenEXR's C++ reader reads 4 and
// parses on from there, where a hidden string attribute declares 1.8 GB; a
// walk of the declared sizes alone would skip over it.
TEST(ReaderAllocation, ValueShorterThanItsDeclaredSizeCannotHideAHugeAttribute) {
  expect_exr_refused_within_bound("exr_int_declared_24_bytes_hides_1.8GB_string.exr",
                                  "Invalid size 24");
}

// A channel list ending (its empty name) before its declared size: both
// OpenEXR readers parse on from the end of its content, into a string
// attribute declaring 1.8 GB that the declared sizes skipped.
TEST(ReaderAllocation, ChannelListEndingEarlyCannotHideAHugeAttribute) {
  expect_exr_refused_within_bound("exr_chlist_ends_early_hides_1.8GB_string.exr",
                                  "'x', type 'string': Invalid size 1879048192");
}

// Read as float, OpenImageIO converts through a buffer of at least 256 rows:
// 77 MB for a one-row PNG of 100,000 pixels (300 KB of pixels).
TEST(ReaderAllocation, OneRowImageIsReadWithoutARowBuffer256High) {
  const fs::path file = fs::temp_directory_path() / "one_row.png";
  drift::render::Image row(100000, 1, {"R", "G", "B"}, 0.25f);
  drift::render::write_png(row, file);
  g_largest = 0;
  const drift::render::Image back = drift::render::read_image(file);
  EXPECT_LT(g_largest.load(), std::size_t{8} << 20);
  EXPECT_EQ(back.width, 100000);
  EXPECT_GT(back.at(99999, 0, 2), 0.1f);  // decoded, not left zero
  EXPECT_EQ(back.at(99999, 0, 2), back.at(0, 0, 2));
}

// A PLY header of 889,850,951 vertices and no properties: 0 bytes a row, so a
// check of the declared rows against the file's size passes it, and a reader
// trusting it would allocate 3.6 GB for a column (fuzz_ply, 2026-11-25).
TEST(ReaderAllocation, PlyVerticesWithoutCoordinatesAreRefusedBeforeAllocating) {
  const fs::path file = regression("ply", "889850951_vertices_no_properties.ply");
  std::size_t largest = 0;
  const std::string m =
      refusal(file, largest, [](const fs::path& f) { drift::terrain::read_ply(f); });
  EXPECT_LT(largest, kBound) << m;
  EXPECT_NE(m.find("declares no float vertex property 'x'"), std::string::npos) << m;
}

}  // namespace
