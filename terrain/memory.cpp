#include "terrain/memory.h"

#include <cstdio>
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

std::uint64_t available_memory_bytes() { return std::min(meminfo_available(), cgroup_limit()); }

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
