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
#include <utility>
#include <vector>

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

namespace {
// What HeldMemory objects keep (guarded by g_estimate_mutex).
std::uint64_t g_held = 0;
std::vector<std::string> g_held_what;
}  // namespace

HeldMemory::HeldMemory(std::uint64_t bytes, std::string what)
    : bytes_(bytes), what_(std::move(what)) {
  const std::lock_guard<std::mutex> lock(g_estimate_mutex);
  g_held += bytes_;
  g_held_what.push_back(what_ + " (" + human_bytes(bytes_) + ")");
}

HeldMemory::~HeldMemory() {
  const std::lock_guard<std::mutex> lock(g_estimate_mutex);
  g_held -= bytes_;
  const std::string entry = what_ + " (" + human_bytes(bytes_) + ")";
  const auto it = std::find(g_held_what.begin(), g_held_what.end(), entry);
  if (it != g_held_what.end()) g_held_what.erase(it);
}

void require_memory(std::uint64_t asked, const std::string& asked_what, const std::string& fix) {
  std::uint64_t bytes = asked;
  std::string what = asked_what;
  {
    const std::lock_guard<std::mutex> lock(g_estimate_mutex);
    if (g_held > 0) {
      // Saturating: a hostile size near 2^64 must not wrap to a small one.
      constexpr std::uint64_t kMost = std::numeric_limits<std::uint64_t>::max();
      bytes = asked > kMost - g_held ? kMost : asked + g_held;
      what += " beside";
      for (std::size_t i = 0; i < g_held_what.size(); ++i)
        what.append(i == 0 ? " " : " and ").append(g_held_what[i]);
    }
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
