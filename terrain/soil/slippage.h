// Soil slippage on the multi-level heightfield (paper 004, sec. 3.2.3, with
// Li & Moshell's slices, sec. 2.1.2).
//
// Every piled span meets the piled spans of its 8 neighbouring columns
// (diagonals at sqrt(2) voxels, so that cones come out round rather than
// square) in soil slices: two piles with a non-negative intersection of
// heights (eq. 31, zero admitted so that soil slides across a body's top onto a
// pile level with it), rise h = min(T_high, B_next above the low pile) -
// T_low (eq. 32). A pile resting on a body with no span beside its bottom
// gets an edge span of zero height there (fig. 34-35), so its soil slides off
// and falls. Each slice with a failure plane (eq. 4) accelerates its wedge
// (eqs. 8-9, a = g f / W) and moves eq. 10's height from the higher pile to
// the lower; the slice's speed is kept from step to step and reset when it is
// stable. Each pile's net change is applied to its density column from its
// top voxel (fig. 36): removed downwards, added upwards.
//
// Each slice is computed once, by its higher column, and the lower column
// gathers what it receives, so the same bits come out on any thread count and
// the soil taken equals the soil given (mass is conserved).
#pragma once

#include <vector>

#include "terrain/soil/height_spans.h"
#include "terrain/soil/soil_state.h"
#include "terrain/soil/soil_type.h"

namespace drift::soil {

class Slippage {
 public:
  static constexpr int kMaxPiles = 4;  // per column that can slide; higher piles stay put
  static constexpr int kDirections = 8;
  // Largest share of a wedge one slice moves in a step: 8 slices may drain a
  // pile at once, and together they must not take it below its neighbours.
  static constexpr double kMaxShare = 0.125;

  explicit Slippage(const terrain::Grid3Shape& shape);

  // One slippage step on state.rho (psi read).
  void step(SoilState& state, const SoilType& soil, double gravity, double dt);

  const HeightSpans& spans() const { return spans_; }

 private:
  struct Out {
    float dh = 0;              // voxels of height moved out
    std::int16_t target = -1;  // span index in the neighbour column; -1 edge span
    std::int16_t edge_voxel = -1;
  };
  // What every slice of a step shares: voxel size (m), friction angle (rad),
  // effective cohesion, unit weight, gravity, time step and the grid's top.
  struct SliceConstants {
    double voxel, phi, cohesion, gamma, gravity, dt;
    float grid_top;
  };
  void compute_slices(const SoilType& soil, double gravity, double dt);
  // The slices of pile `pile` (span p) of column (x, y) towards its 8 neighbours.
  void slide_pile(int x, int y, int pile, const HeightSpan& p, const SliceConstants& k);
  // One slice from pile p to the column n along direction d: o.dh and the speed v.
  void slide_slice(const HeightSpan& p, const HeightSpan* n, int ncount, int d,
                   const SliceConstants& k, Out& o, float& v) const;
  void apply(SoilState& state) const;

  terrain::Grid3Shape shape_;
  HeightSpans spans_;
  std::vector<Out> out_;      // columns x kMaxPiles x kDirections
  std::vector<float> speed_;  // same layout: slice speeds, m/s
};

}  // namespace drift::soil
