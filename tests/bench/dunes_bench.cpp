// Sand transport throughput: cell-steps per second of the ripple and dune
// models (saltation, creep and the per-step avalanching) at the sizes users
// simulate, along the grid and obliquely, with peak memory (the process's
// peak so far: benchmarks run in order, so it only grows).
#include <benchmark/benchmark.h>

#include "dunes/sand_model.h"
#include "tests/bench/peak_memory.h"

namespace {

using drift::dunes::Model;

// `wind_from`: 270 blows along the grid; 300 is 30 degrees off it (the sand
// on the turned wind lattice, rows of 30 grid widths at 1024^2).
void run_steps(benchmark::State& state, Model model, double wind_from = 270.0) {
  drift::dunes::SandOptions o = drift::dunes::default_options(model);
  o.size = static_cast<int>(state.range(0));
  o.wind_from_deg = wind_from;
  drift::terrain::HeightField h = drift::dunes::initial_field(o);
  // A run keeps its scratch memory from step to step, as run() does.
  drift::dunes::Workspace workspace;
  // Develop the field first: a developed field avalanches more than noise.
  for (int s = 0; s < 20; ++s) drift::dunes::step(h, o, workspace);
  for (auto _ : state) {
    drift::dunes::step(h, o, workspace);
    benchmark::DoNotOptimize(h.data());
  }
  state.counters["cell_steps/s"] =
      benchmark::Counter(static_cast<double>(h.size()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
  state.counters["peak_MiB"] = drift::bench::peak_resident_mib();
}

void BM_RippleStep(benchmark::State& state) { run_steps(state, Model::Ripples); }
void BM_DuneStep(benchmark::State& state) { run_steps(state, Model::Dunes); }
void BM_RippleStepOblique(benchmark::State& state) { run_steps(state, Model::Ripples, 300.0); }
void BM_DuneStepOblique(benchmark::State& state) { run_steps(state, Model::Dunes, 300.0); }
BENCHMARK(BM_RippleStep)
    ->Arg(256)
    ->Arg(1024)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_DuneStep)
    ->Arg(256)
    ->Arg(1024)
    ->Arg(4096)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_RippleStepOblique)->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DuneStepOblique)->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
