// The voxel soil stage (paper 004): one step is the thesis's Algorithm 1.
//
//   move rigid bodies to t + dt; psi = static collision field + voxelised bodies
//   deformation: force application (eq. 33), alpha propagation iterations (eqs. 34-35)
//   advection (eqs. 23-28), overflow resolution (fig. 30), settle (eq. 17 exactly)
//   gravity (eq. 29)
//   slippage on the multi-level heightfield (sec. 3.2.3, Li & Moshell)
//
// Options (defaults, units, ranges):
// | option                 | default   | unit  | range / meaning                          |
// |------------------------|-----------|-------|------------------------------------------|
// | dt                     | 1/60      | s     | (0, 1]; soil moves at most 1 voxel a step |
// | gravity                | 9.81      | m/s^2 | [0, 100]                                 |
// | propagation_iterations | 4         |       | [0, 64], the thesis's alpha              |
// | overflow               | Up        |       | fig. 30's heuristic                      |
// | overflow_passes        | 4         |       | [0, 64]                                  |
// | settle                 | true      |       | carry leftover overflow up (eq. 17 holds)|
// | slippage               | true      |       | Li & Moshell slippage on                 |
// | soil                   | dry sand  |       | see soil_type.h                          |
#pragma once

#include <memory>
#include <vector>

#include "terrain/soil/advection.h"
#include "terrain/soil/primitives.h"
#include "terrain/soil/slippage.h"
#include "terrain/soil/soil_state.h"
#include "terrain/soil/soil_type.h"

namespace drift::soil {

struct SoilOptions {
  double dt = 1.0 / 60.0;
  double gravity = 9.81;
  int propagation_iterations = 4;
  OverflowHeuristic overflow = OverflowHeuristic::Up;
  int overflow_passes = 4;
  bool settle = true;
  bool slippage = true;
  SoilType soil;
};

// Throws drift::Error naming the option, its value and the range.
void validate(const SoilOptions& options);

class SoilSimulation {
 public:
  // The state must already hold the initial soil and the static collision
  // field (psi_static); moving bodies are `bodies` (static ones may be given
  // too: they are voxelised once into psi_static here).
  SoilSimulation(SoilState state, std::vector<RigidObject> bodies, const SoilOptions& options);

  void step();
  void run(int steps) {
    for (int i = 0; i < steps; ++i) step();
  }

  const SoilState& state() const { return state_; }
  SoilState& state() { return state_; }
  const SoilOptions& options() const { return options_; }
  double time() const { return time_; }
  long steps() const { return steps_; }
  const std::vector<RigidObject>& bodies() const { return bodies_; }
  const HeightSpans& spans() const { return slippage_.spans(); }

  // Rebuilds psi for the bodies at the current time (done by step(); public
  // so a fresh simulation can be inspected before its first step).
  void rebuild_collision_field();

 private:
  SoilState state_;
  std::vector<RigidObject> bodies_;  // the moving ones
  SoilOptions options_;
  Slippage slippage_;
  double time_ = 0;
  long steps_ = 0;
};

// Adds soil where the union of `primitives` (at `position`) covers voxels,
// up to the room the collision field leaves (rho + psi <= 1).
void add_soil(SoilState& state, const std::vector<Primitive>& primitives,
              const Eigen::Vector3d& position);

}  // namespace drift::soil
