// The fuzz targets: one function per reader of outside input, each taking the
// bytes of one file. A target returns normally when the reader accepts the file
// or refuses it with drift::Error; anything else (a crash, a sanitizer report,
// another exception, a hang) is a finding. Built two ways: as libFuzzer
// binaries (fuzz_main.cpp, scripts/fuzz.sh) and into the suite's replay of the
// regression inputs under tests/fuzz/regressions/<target>/ (fuzz_replay_test).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace drift::fuzz {

struct Target {
  const char* name;
  void (*run)(const std::uint8_t* data, std::size_t size);
};

// Every target, by name: raster, scene, objects, track, scenario, obj, ply, mesh,
// image.
const std::vector<Target>& targets();

// For the libFuzzer binaries: a target skips the costly part (a simulation)
// for inputs whose cost grows with their values without reaching new code,
// so that a fuzzer explores; the suite's replay runs every input whole.
void bound_work_per_input();

// Runs target `name` on one input; returns false if there is no such target.
bool run_target(const std::string& name, const std::uint8_t* data, std::size_t size);

}  // namespace drift::fuzz
