#include "tests/bench/peak_memory.h"

#include <fstream>
#include <string>

namespace drift::bench {

namespace {

std::uint64_t status_bytes(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string key;
  while (in >> key) {
    if (key == field) {
      std::uint64_t kb = 0;
      in >> kb;
      return kb * 1024;
    }
    std::string rest;
    std::getline(in, rest);
  }
  return 0;
}

}  // namespace

std::uint64_t peak_resident_bytes() { return status_bytes("VmHWM:"); }

std::uint64_t resident_bytes() { return status_bytes("VmRSS:"); }

void reset_peak_resident() { std::ofstream("/proc/self/clear_refs") << "5"; }

}  // namespace drift::bench
