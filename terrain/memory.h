// How much memory the machine can give us, so that allocations users ask for
// (a huge raster, a 100k x 100k render) are refused with a clear message
// before they are attempted.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace drift {

// MemAvailable from /proc/meminfo, or the cgroup limit if that is lower; bytes.
std::uint64_t available_memory_bytes();

// Throws drift::Error if `bytes` exceeds what is available (with a safety margin),
// naming `what` (e.g. "raster 'big.tif' (100000 x 100000 float32)") and the fix.
void require_memory(std::uint64_t bytes, const std::string& what, const std::string& fix);

std::string human_bytes(std::uint64_t bytes);

// Memory a run keeps while later, separate checks are made (render's terrain
// while its image is allocated): while one is alive, every require_memory
// call asks for its own bytes plus every held amount, and names what is held,
// so that the run's estimate adds them (render's terrain and image checks were
// separate, and the larger alone was the estimate: MemoryEstimate.
// RenderLargeImageWithLargeBudget). Not copyable; held amounts add up.
class HeldMemory {
 public:
  HeldMemory(std::uint64_t bytes, std::string what);
  ~HeldMemory();
  HeldMemory(const HeldMemory&) = delete;
  HeldMemory& operator=(const HeldMemory&) = delete;

 private:
  std::uint64_t bytes_;
  std::string what_;
};

// The run's memory estimate: the largest amount any require_memory call of this
// process asked for, and what it named. Each subcommand's largest check counts
// every buffer its inputs size that is alive at its peak (docs/outputs.md), so
// this is what the run needs beyond the program itself; with
// DRIFT_MEMORY_REPORT=1 drift prints it on exit (the memory tests compare it
// with the measured peak). 0 and "" before any check.
std::uint64_t memory_estimate_bytes();
std::string memory_estimate_what();

// The documented forms of a size such as DRIFT_MEMORY_LIMIT: a whole or decimal
// number of bytes, optionally followed by K, M, G or T (powers of 1024), with or
// without "iB" or "B" ("512M", "8GiB", "1.5T", "4096"), no spaces, more than 0
// and below 16 EiB. Returns the bytes, or nothing for anything else ("8 G", "1X",
// "abc", "0", "-5", "nan", "1e3").
std::optional<std::uint64_t> parse_byte_size(std::string_view text);

// Checks DRIFT_MEMORY_LIMIT once: "" if it is unset or well formed, else the
// message naming the variable, its value and the accepted forms. The command line
// calls it before anything else and exits 2 on a message; available_memory_bytes()
// throws drift::Error with the same message, so no caller reads a bad value as
// "no cap".
std::string memory_limit_problem();

}  // namespace drift
