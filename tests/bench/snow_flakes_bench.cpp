// Cost of the flake pattern of thin snow (render/snow_flakes.h) per shading
// point: point-sampled (every flake whole, the close-up case) at coverages
// from a dusting to nearly full, and filtered (a footprint past the flakes,
// only the clumps' noise). Points spread over 100 m in UTM-sized coordinates.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "render/snow_flakes.h"

namespace {

std::vector<Eigen::Vector3d> points() {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0.0, 100.0);
  std::vector<Eigen::Vector3d> p(1 << 16);
  for (auto& q : p) q = {746000.0 + u(rng), 4030000.0 + u(rng), 2000.0};
  return p;
}

void BM_FlakeCover(benchmark::State& state) {
  static const std::vector<Eigen::Vector3d> p = points();
  const float coverage = static_cast<float>(state.range(0)) / 100.0f;
  const double footprint = static_cast<double>(state.range(1)) / 1000.0;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        drift::render::flake_cover(p[i++ & (p.size() - 1)], {0, 0, 1}, coverage, footprint));
  }
  state.SetItemsProcessed(state.iterations());
}
// Arguments: coverage in %, footprint in mm (0: point samples; 50: filtered).
BENCHMARK(BM_FlakeCover)->ArgsProduct({{5, 30, 60, 90, 99}, {0, 50}});

}  // namespace

BENCHMARK_MAIN();
