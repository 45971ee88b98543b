#include "terrain/memory.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <mutex>
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

// DRIFT_MEMORY_LIMIT caps what a run may use (docs/outputs.md), e.g. for batch
// jobs sharing a machine, and for the fuzz targets.
// An empty value, as an unset shell variable gives, means no cap.
static std::uint64_t user_limit() {
  const char* text = std::getenv("DRIFT_MEMORY_LIMIT");
  if (!text || !*text) return std::numeric_limits<std::uint64_t>::max();
  const std::optional<std::uint64_t> bytes = parse_byte_size(text);
  if (!bytes) throw Error(memory_limit_problem());
  return *bytes;
}

std::optional<std::uint64_t> parse_byte_size(std::string_view text) {
  // Digits with at most one decimal point: no sign, exponent, hex, inf or nan,
  // which strtod would accept.
  std::size_t i = 0;
  bool digits = false, point = false;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c >= '0' && c <= '9') {
      digits = true;
    } else if (c == '.' && !point) {
      point = true;
    } else {
      break;
    }
  }
  if (!digits) return std::nullopt;
  const std::string number(text.substr(0, i));
  std::string_view unit = text.substr(i);
  double scale = 1.0;
  if (!unit.empty()) {
    const std::string_view prefixes = "KMGT";
    const std::size_t p = prefixes.find(static_cast<char>(std::toupper(unit[0])));
    if (p != std::string_view::npos) {
      scale = std::pow(1024.0, static_cast<double>(p + 1));
      unit.remove_prefix(1);
      if (unit == "iB" || unit == "ib" || unit == "B" || unit == "b") unit = {};
    } else if (unit == "B" || unit == "b") {
      unit = {};
    }
  }
  if (!unit.empty()) return std::nullopt;
  const double bytes = std::strtod(number.c_str(), nullptr) * scale;
  // Below 2^64 (16 EiB) and at least one byte.
  if (!(bytes >= 1.0) || !(bytes < 18446744073709551616.0)) return std::nullopt;
  return static_cast<std::uint64_t>(bytes);
}

std::string memory_limit_problem() {
  const char* text = std::getenv("DRIFT_MEMORY_LIMIT");
  if (!text || !*text || parse_byte_size(text)) return {};
  return std::string("DRIFT_MEMORY_LIMIT is '") + text +
         "', which is not a memory size; give bytes or a number with K, M, G or T (optionally "
         "followed by iB), e.g. DRIFT_MEMORY_LIMIT=8G, or unset it for no cap";
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

namespace {
std::atomic<std::uint64_t> g_estimate{0};
std::mutex g_estimate_mutex;
std::string g_estimate_what;
}  // namespace

std::uint64_t memory_estimate_bytes() { return g_estimate.load(); }

std::string memory_estimate_what() {
  const std::lock_guard<std::mutex> lock(g_estimate_mutex);
  return g_estimate_what;
}

void require_memory(std::uint64_t bytes, const std::string& what, const std::string& fix) {
  {
    const std::lock_guard<std::mutex> lock(g_estimate_mutex);
    if (bytes > g_estimate.load()) {
      g_estimate.store(bytes);
      g_estimate_what = what;
    }
  }
  // Leave a quarter of what is free for the rest of the process and the system.
  const std::uint64_t avail = available_memory_bytes();
  const std::uint64_t budget = avail - avail / 4;
  if (bytes > budget) {
    throw Error(what + " needs " + human_bytes(bytes) + " but only " + human_bytes(avail) +
                " is available; " + fix);
  }
}

}  // namespace drift
