// Marks that objects leave in soft ground: footprints, tyre tracks, dragged
// objects in sand, mud and snow (paper 000, Onoue & Nishita, after Sumner,
// O'Brien & Hodgins 1999). One simulation step, per object and sub-step:
//   1. collision by z-buffer: the object's bottom over the ground's cells,
//      looking up from below (object_bottom.h; 3.3), swept when dragged;
//   2. compression and displacement onto the contact's ring and outwards
//      along a Euclidean distance transform, the object's bottom a hard
//      ceiling (displacement.h; 3.4);
//   3. erosion from the contact outwards where slopes exceed the material's
//      angle, never above the object's bottom (terrain/slope_relax.h; 3.5),
//      for every sub-step but the last, whose erosion is the step's:
// at the end of the step, erosion of the cells remembered from this and
// earlier steps and of the cells objects hold (remembered while held), so
// material goes on sliding after an object leaves, however long it stood
// (3.5). The options' table is marks_parameters.h.
// Objects far from a camera, or marked so by the user, work on a half or
// quarter resolution copy of their window, written back by linear
// interpolation (multires.h; 3.6).
//
// Options (units, defaults, ranges):
//   step            s     0.1      (0, 3600]  simulated time per step
//   memory_steps    steps 20       [0, 1e6]   how long a cell that slid keeps relaxing
//                                             (a held cell: counted from the release)
//   erosion_passes  -     100      [1, 1e5]   most relaxation passes per erosion (one a step,
//                                             and one a sub-step before the last)
//   margin          cells 4        [2, 1000]  free cells around a footprint for rims
//   renderer        -     cpu      cpu|opengl how the object's bottom is rendered
//   seed            -     0        any        roughness draws (erosion, Material::sigma)
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "terrain/grid.h"
#include "terrain/marks/ground_material.h"
#include "terrain/marks/marks_options.h"
#include "terrain/marks/object_bottom.h"
#include "terrain/marks/object_geometry.h"
#include "terrain/marks/trajectory.h"
#include "terrain/mesh.h"
#include "terrain/progress.h"

namespace drift::marks {

// How an object moving more than a cell per step is handled (paper 000,
// table 1): swept (default), cut into sub-steps of at most a cell each, or
// simply placed at each step (leaves streaks: for comparison only).
enum class Motion { Sweep, SubSteps, Place };

struct MarkObject {
  std::string name;                  // for messages
  terrain::Mesh mesh;                // in its own frame (m), scaled and turned z-up
  Trajectory trajectory;             // keyframes in the ground's CRS
  bool follow_ground = false;        // keyframe z = height of the origin above the ground
  std::optional<Material> material;  // the ground's material where it walks
  Motion motion = Motion::Sweep;
  int resolution = 1;  // 1 full, 2 half, 4 quarter; 0: chosen from the camera
};

struct StepReport {
  double collided = 0.0, displaced = 0.0, compressed = 0.0;  // m3
  int contact_cells = 0;
  int substeps = 0;
  // The object's lowest clearance above the ground at the step's end (m; <= 0:
  // it touches), with its bottom and the ground there (m); +inf when it is
  // not over the field.
  double clearance = std::numeric_limits<double>::infinity();
  double bottom = 0.0, ground = 0.0;
  bool touched() const { return clearance <= 1e-9 * std::max(1.0, std::abs(ground)); }
};

// The state of a run, for callers that drive it step by step (benchmarks,
// tests, interactive tools). Not thread-safe; one per thread.
class MarksSimulation {
 public:
  MarksSimulation(const terrain::HeightField& ground, MaterialField materials,
                  const MarksOptions& options);
  ~MarksSimulation();

  // The object (its shape made once with ObjectShape::of) moves from `from`
  // to `to` within the current step; `first`: it appears at `to` (no motion).
  StepReport move(const ObjectShape& shape, const MarkObject& object, const Pose& from,
                  const Pose& to, bool first);
  // Ends the step: erosion of remembered cells under the objects' last bottoms.
  void end_step();

  const terrain::Grid<double>& heights() const { return heights_; }
  const terrain::Grid<float>& disturbed() const { return disturbed_; }
  const MaterialField& materials() const { return materials_; }
  const GridFrame& frame() const { return frame_; }
  int step_index() const { return step_; }
  terrain::HeightField heights_as_float() const;

  // The level (1, 2, 4) an object at `where` is worked at.
  int resolution_for(const MarkObject& object, const Eigen::Vector3d& where) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  terrain::Grid<double> heights_;
  terrain::Grid<float> disturbed_;
  MaterialField materials_;
  GridFrame frame_;
  MarksOptions options_;
  int step_ = 0;
  friend struct Impl;
};

// Per object over the run: how many of its steps it touched the ground in, and
// its lowest point against the ground beneath when it came nearest (for the
// warning about objects that never touch: a typo in a height).
struct ObjectReport {
  std::string name;
  int steps = 0, contact_steps = 0;
  double clearance = std::numeric_limits<double>::infinity();  // m, +inf: never over the field
  double bottom = 0.0, ground = 0.0;                           // m, where it came nearest
};

// One object's step: what it pressed (m3) and whether it touched.
struct ObjectStep {
  int step = 0, object = 0;
  double collided = 0.0, displaced = 0.0, compressed = 0.0;
  bool contact = false;
};

struct MarksReport {
  int steps = 0;
  int contact_steps = 0;  // steps in which some object touched the ground
  double collided = 0.0, displaced = 0.0, compressed = 0.0;  // m3 over the run
  std::vector<ObjectReport> objects;                         // in the objects' order
  // Per object and step, on a window of a larger raster only (options.window):
  // marks_blocks.h adds up each step once, from a window that holds it whole.
  std::vector<ObjectStep> object_steps;
};

struct MarksResult {
  terrain::HeightField heights;
  terrain::Grid<float> disturbed;  // m of height compressed, displaced or slid per cell
  MarksReport report;
};

// Called after every step with its index and the field (for --frames); return
// false to cancel.
using StepFn = std::function<bool(int step, const MarksSimulation& state)>;

// Where an object stands at time t (s, clamped to its keyframes), as the run
// places it: its keyframes' pose, raised by the ground under its origin when
// it follows the ground.
Pose object_pose(const MarkObject& object, const terrain::HeightField& ground, double t);

// The ground's height (m) under a point of the ground's CRS, for objects that
// follow the ground; a run on a window of a larger raster (marks_blocks.h)
// reads it from the whole raster, as a run on the whole raster would.
using GroundAt = std::function<double(double x, double y)>;
Pose object_pose(const MarkObject& object, const GroundAt& ground_at, double t);

// The objects' meshes at their poses at time t, in the ground's CRS measured
// from the raster's north-west corner (the mesh's origin), merged into one (issue 32 item 7: a
// scene shows the mark with the thing that made it, placed by the same keyframes). Objects whose
// keyframes do not reach t stand at their nearest keyframe.
terrain::Mesh posed_objects(const std::vector<MarkObject>& objects,
                            const terrain::HeightField& ground, double t);

// The time the run ends: the last keyframe of any object (s).
double run_end(const std::vector<MarkObject>& objects);

// Runs every object along its keyframes from the first keyframe of any to the
// last. Throws drift::Error for bad options, trajectories or meshes, and when
// the state does not fit in memory (checked before allocating).
MarksResult simulate_marks(const terrain::HeightField& ground,
                           const std::vector<MarkObject>& objects, MaterialField materials,
                           const MarksOptions& options, const StepFn& on_step = {},
                           const ProgressFn& progress = no_progress);

// The same with the height objects that follow the ground stand on taken from
// `ground_at` (empty: from `ground`), for a window of a larger raster.
MarksResult simulate_marks_on(const terrain::HeightField& ground,
                              const std::vector<MarkObject>& objects, MaterialField materials,
                              const MarksOptions& options, const GroundAt& ground_at,
                              const StepFn& on_step = {}, const ProgressFn& progress = no_progress);

}  // namespace drift::marks
