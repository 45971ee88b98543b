// Soil slippage on the multi-level heightfield (paper 004, sec. 3.2.3, with
// Li & Moshell's slices, sec. 2.1.2).
//
// Every piled span meets the piled spans of 16 neighbouring columns in soil
// slices: the 8 around it (diagonals at sqrt(2) voxels) and the 8 a knight's
// move away (sqrt(5) voxels), so that the slopes' lattice metric is within
// 3 % of the Euclidean one and cones come out round (with 8 directions a
// collapsed column rests as an octagonal pyramid whose half-height radius
// varies 8-18 % with direction). Two piles form a slice with a non-negative
// intersection of heights (eq. 31, zero admitted so that soil slides across
// a body's top onto a pile level with it), rise h = min(T_high, B_next above
// the low pile) - T_low (eq. 32). A knight's slice needs the two columns it
// crosses to be open between the two piles (soil never hops through a body).
// A pile resting on a body with no span beside its bottom gets an edge span
// of zero height there (fig. 34-35), so its soil slides off and falls.
//
// Failure (docs/soil.md, Method 6, "Failure in metres": a decision where the
// thesis is silent): Li & Moshell's
// factor of safety is taken over the pile's real height in metres, not over
// one voxel's step, so cohesion acts the same at any voxel size. Each pile
// follows its steepest descent to the toe of its slope (the first pile
// without soil, or a flat) and its steepest ascent to the crest; the slope
// height H = crest - toe gives the steepest angle the slope stands at
// (rest_angle, Culmann's wedge: phi without cohesion, vertical below the
// critical height 4 c / gamma tan(45 + phi / 2)). A slice whose slope is
// steeper fails on the plane at that angle: the wedge above it accelerates
// (eqs. 8-9, a = g f / W) and eq. 10's height moves from the higher pile to
// the lower; the pile's speed is kept from step to step.
//
// A pile slides along its steepest descent, not along each lattice direction
// on its own: the slope between two neighbouring directions is the plane
// through their two slices (D-infinity's facets, Tarboton 1997, over the 16
// directions), the failure test and eq. 10's flux use that true slope, and the
// flux is split between the two bracketing directions so that it points down
// the true gradient, each direction's soil divided by its run (issue 33, item
// 4: a collapsed column's half-height radius varied 6.4 % with direction when
// each direction failed on its own slope, 1.5 % now). A sliding pile stops
// once its slope is within kStopDeg of the rest angle (or its wedge is under
// kStopHeight thick); a pile at rest starts again only kStaticDeg above it
// (static friction), so piles come to rest instead of creeping for ever.
// Each pile's change is applied to its density column from its top voxel
// (fig. 36): what it gives is removed downwards first, then what it receives
// is added upwards from there into open voxels (never through a body). The
// soil keeps its moisture: what leaves a pile carries the moisture of the
// voxels it left, and the pile's own moisture sets its apparent cohesion.
//
// Each slice is computed once, by its higher column, and the lower column
// gathers what it receives, so the same bits come out on any thread count and
// the soil taken equals the soil given (mass is conserved).
#pragma once

#include <cstdint>
#include <vector>

#include "terrain/soil/height_spans.h"
#include "terrain/soil/soil_state.h"
#include "terrain/soil/soil_type.h"

namespace drift::soil {

class Slippage {
 public:
  static constexpr int kMaxPiles = 4;  // per column that can slide; higher piles stay put
  static constexpr int kDirections = 16;
  // Largest share of its wedge a pile moves in a step: its neighbours uphill
  // feed it at once, and together they must not take it below them.
  static constexpr double kMaxShare = 0.25;
  // Static friction: the angle of maximum stability of a granular slope lies
  // about 2 degrees above its angle of repose (Jaeger, Nagel & Behringer 1996,
  // "Granular solids, liquids, and gases", Rev. Mod. Phys. 68, sec. III).
  static constexpr double kStaticDeg = 2.0;
  // A sliding slice stops this close to its rest angle, or once the wedge
  // above the rest plane is thinner than kStopHeight metres: otherwise the
  // wedges of a whole flank feed one another, shrink geometrically and never
  // reach it (the creep of issue 33: moved soil halving every 5 s).
  static constexpr double kStopDeg = 0.5;
  static constexpr double kStopHeight = 0.002;
  // Soil (voxels) a pile needs to count as part of a slope; the toe of a
  // slope is the first pile below it with less.
  static constexpr float kSlopeSoil = 0.02f;

  explicit Slippage(const terrain::Grid3Shape& shape);

  // Bytes a column of the grid costs here (its spans and every per-pile
  // array), counted in the run's memory check (soil_run_bytes).
  static std::uint64_t bytes_per_column();

  // One slippage step on state.rho (psi read).
  void step(SoilState& state, const SoilType& soil, double gravity, double dt);

  const HeightSpans& spans() const { return spans_; }
  // Per column, non-zero where the last step laid soil that found no room
  // (a pile capped by a body that turned over it): the simulation settles
  // those columns so eq. 17 holds after every step.
  const std::vector<std::uint8_t>& overfilled() const { return overfilled_; }
  bool any_overfilled() const { return any_overfilled_; }
  // Rest angle (radians) of pile `pile` of column `column` from the last step
  // (-1 if the column has no such pile).
  double rest_angle_of(std::size_t column, int pile) const;

 private:
  struct Out {
    float dh = 0;              // voxels of height moved out
    std::int16_t target = -1;  // span index in the neighbour column; -1 edge span
    std::int16_t edge_voxel = -1;
  };
  // What every slice of a step shares: voxel size (m), unit weight, gravity,
  // time step and the grid's top.
  struct SliceConstants {
    double voxel, gamma, gravity, dt;
    float grid_top;
  };
  // Per pile ("node" = column * kMaxPiles + pile): its span, the neighbours
  // of steepest descent and ascent, and from them the rest angle.
  void link_piles();
  void rest_angles(const SoilType& soil);
  void compute_slices(const SoilType& soil, double gravity, double dt);
  // The slices of pile `pile` (span p) of column (x, y) towards its 16 neighbours.
  void slide_pile(int x, int y, int pile, const HeightSpan& p, const SliceConstants& k);
  // The slice from pile p to the column n: its rise (eq. 32, voxels; 0 if
  // none forms) and its target in o.
  double slice_rise(const HeightSpan& p, const HeightSpan* n, int ncount, const SliceConstants& k,
                    Out& o) const;
  // A knight's slice from (x, y) along d crosses two columns: both must hold
  // a pile below p's top with nothing solid between it and p's top.
  bool open_path(int x, int y, int d, const HeightSpan& p) const;
  // Per pile the mass-weighted moisture of its span (its apparent cohesion).
  void pile_moisture(const SoilState& state);
  void apply(SoilState& state);

  terrain::Grid3Shape shape_;
  HeightSpans spans_;
  std::vector<Out> out_;                            // columns x kMaxPiles x kDirections
  std::vector<float> speed_;                        // per node: slide speed, m/s
  std::vector<std::int8_t> pile_span_;              // per node: span index, -1 none
  std::vector<int> down_, up_, toe_, crest_, hop_;  // per node
  std::vector<float> rest_;                         // per node: rest angle, rad
  std::vector<float> pile_wet_;                     // per node: moisture of the pile's upper third
  std::vector<float> out_wet_;                      // per node: moisture of what it gave
  std::vector<int> out_from_;                       // per node: lowest voxel it gave from
  std::vector<std::uint8_t> sends_;                 // per column: some pile gives soil
  std::vector<std::uint8_t> overfilled_;            // per column
  bool any_overfilled_ = false;
};

// Bytes a whole run on `shape` holds at its peak, what make_simulation checks
// first: the state, the slippage's heightfield (per column), the terrain's
// heights, and the surface's extraction (two density copies and the mesh).
// Within 25 % of the measured peak (MemoryEstimate.SoilCountsItsHeightfieldAndSurface).
std::uint64_t soil_run_bytes(const terrain::Grid3Shape& shape);

}  // namespace drift::soil
