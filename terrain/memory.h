// How much memory the machine can give us, so that allocations users ask for
// (a huge raster, a 100k x 100k render) are refused with a clear message
// before they are attempted.
#pragma once

#include <cstdint>
#include <string>

namespace drift {

// MemAvailable from /proc/meminfo, or the cgroup limit if that is lower; bytes.
std::uint64_t available_memory_bytes();

// Throws drift::Error if `bytes` exceeds what is available (with a safety margin),
// naming `what` (e.g. "raster 'big.tif' (100000 x 100000 float32)") and the fix.
void require_memory(std::uint64_t bytes, const std::string& what, const std::string& fix);

std::string human_bytes(std::uint64_t bytes);

}  // namespace drift
