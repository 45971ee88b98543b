#include "terrain/memory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "terrain/error.h"

namespace drift {

namespace {

std::uint64_t meminfo_available() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::uint64_t kb = 0;
  std::string unit;
  while (in >> key >> kb >> unit) {
    if (key == "MemAvailable:") return kb * 1024;
  }
  return std::numeric_limits<std::uint64_t>::max();
}

std::uint64_t cgroup_limit() {
  for (const char* path :
       {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(path);
    std::string s;
    if (in >> s && s != "max") {
      try {
        return std::stoull(s);
      } catch (...) {
      }
    }
  }
  return std::numeric_limits<std::uint64_t>::max();
}

}  // namespace

// DRIFT_MEMORY_LIMIT caps what a run may use (bytes, or with K, M, G suffix),
// e.g. for batch jobs sharing a machine, and for the fuzz targets.
std::uint64_t user_limit() {
  const char* text = std::getenv("DRIFT_MEMORY_LIMIT");
  if (!text || !*text) return std::numeric_limits<std::uint64_t>::max();
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  const double scale = *end == 'K' || *end == 'k'   ? 1024.0
                       : *end == 'M' || *end == 'm' ? 1024.0 * 1024.0
                       : *end == 'G' || *end == 'g' ? 1024.0 * 1024.0 * 1024.0
                                                    : 1.0;
  if (!(v > 0) || !std::isfinite(v * scale)) return std::numeric_limits<std::uint64_t>::max();
  return static_cast<std::uint64_t>(std::min(v * scale, 1.8e19));
}

std::uint64_t available_memory_bytes() {
  return std::min({meminfo_available(), cgroup_limit(), user_limit()});
}

std::string human_bytes(std::uint64_t bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  double v = static_cast<double>(bytes);
  int u = 0;
  while (v >= 1024.0 && u < 4) {
    v /= 1024.0;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %s", v, units[u]);
  return buf;
}

void require_memory(std::uint64_t bytes, const std::string& what, const std::string& fix) {
  // Leave a quarter of what is free for the rest of the process and the system.
  const std::uint64_t avail = available_memory_bytes();
  const std::uint64_t budget = avail - avail / 4;
  if (bytes > budget) {
    throw Error(what + " needs " + human_bytes(bytes) + " but only " + human_bytes(avail) +
                " is available; " + fix);
  }
}

}  // namespace drift
