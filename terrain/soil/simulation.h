// The voxel soil stage (paper 004): one step is the thesis's Algorithm 1.
//
//   move rigid bodies to t + dt; psi = static collision field + voxelised bodies
//   deformation: force application (eq. 33), alpha propagation iterations (eqs. 34-35)
//   advection (eqs. 23-28), overflow resolution (fig. 30), settle (eq. 17 exactly)
//   gravity (eq. 29)
//   slippage on the multi-level heightfield (sec. 3.2.3, Li & Moshell)
//
// Options: the numeric ones (dt, gravity, propagation_iterations, overflow_passes
// and the soil's phi, c, gamma, moisture) with their defaults, units and ranges
// are in one table, terrain/soil/soil_parameters.toml; besides them, overflow
// (fig. 30's heuristic), settle (carry leftover overflow up, so that eq. 17
// holds) and slippage (Li & Moshell slippage on).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "terrain/progress.h"
#include "terrain/soil/advection.h"
#include "terrain/soil/primitives.h"
#include "terrain/soil/slippage.h"
#include "terrain/soil/soil_options.h"
#include "terrain/soil/soil_state.h"
#include "terrain/soil/soil_type.h"

namespace drift::soil {

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
  // A turned or mesh body's coverage (refined_share, 14-57 ms a step at
  // 64^3) as last computed: its pose, voxel box and per-voxel share
  // (x, y, z of the box, z fastest). Reused while the body keeps its
  // orientation and moves by whole voxels (within 1e-6 of a voxel), which
  // includes standing still.
  struct CoverageCache {
    bool valid = false;
    Pose pose;
    VoxelBox box;
    std::vector<float> share;
  };
  void add_body_coverage(const RigidObject& body, CoverageCache& cache);

  SoilState state_;
  std::vector<RigidObject> bodies_;  // the moving ones
  std::vector<CoverageCache> coverage_;
  SoilOptions options_;
  Slippage slippage_;
  double time_ = 0;
  long steps_ = 0;
};

// The soil stage's time loop as one library call, like the other stages'
// entry functions: `steps` steps of `sim`, handing every `frame_every`-th
// state to `frame` (a mesh or VDB writer), progress 0 first and 1 last; a
// progress that returns false cancels (drift::Cancelled).
struct SoilRunOptions {
  int steps = 600;
  int frame_every = 0;  // 0: no frames
  std::function<void(const SoilSimulation&, int step)> frame;
};

struct SoilRunStats {
  int steps = 0;
  double seconds = 0;                        // wall time of the steps (frames included)
  double mass_before = 0, mass_after = 0;    // sum of rho, voxels
  double water_before = 0, water_after = 0;  // sum of rho x moisture, voxels
};

SoilRunStats run_soil(SoilSimulation& sim, const SoilRunOptions& options,
                      const ProgressFn& progress = no_progress);

// Adds soil where the union of `primitives` (at `position`) covers voxels,
// up to the room the collision field leaves (rho + psi <= 1), with moisture
// `moisture` in [0, 1] (mixed by mass with soil already there).
void add_soil(SoilState& state, const std::vector<Primitive>& primitives,
              const Eigen::Vector3d& position, double moisture = 0.0);

}  // namespace drift::soil
