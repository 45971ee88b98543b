// Sand transport throughput: cell-steps per second of the ripple and dune
// models (saltation, creep and the per-step avalanching) at the sizes users
// simulate, with peak memory.
#include <benchmark/benchmark.h>

#include "dunes/sand_model.h"
#include "tests/bench/peak_memory.h"

namespace {

using drift::dunes::Model;

void run_steps(benchmark::State& state, Model model) {
  drift::dunes::SandOptions o = drift::dunes::default_options(model);
  o.size = static_cast<int>(state.range(0));
  drift::terrain::HeightField h = drift::dunes::initial_field(o);
  // Develop the field first: a developed field avalanches more than noise.
  for (int s = 0; s < 20; ++s) drift::dunes::step(h, o);
  for (auto _ : state) {
    drift::dunes::step(h, o);
    benchmark::DoNotOptimize(h.data());
  }
  state.counters["cell_steps/s"] =
      benchmark::Counter(static_cast<double>(h.size()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
  state.counters["peak_MiB"] = drift::bench::peak_resident_mib();
}

void BM_RippleStep(benchmark::State& state) { run_steps(state, Model::Ripples); }
void BM_DuneStep(benchmark::State& state) { run_steps(state, Model::Dunes); }
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

}  // namespace

BENCHMARK_MAIN();
