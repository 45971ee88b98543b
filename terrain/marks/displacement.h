// Compression and displacement of the ground an object presses into (paper
// 000, 3.4, fig. 4, after Sumner et al. 1999). In a collided cell (object
// bottom b below the ground g) the ground drops to b; of the h' = g - b it
// loses, delta h = alpha h' is displaced and the rest is compressed away.
//
// Pressing (the object not dragged): paper 000 routes the displaced material
// from the inside of the contact outwards along a distance transform to the
// ring of free cells just outside. Here each connected contact region hands
// its volume to its ring evenly, in proportion to each ring cell's border with
// the region (issue 32: nearest-edge routing gives a square's edge a rim
// shaped like the sector behind it; real prints have even rims). Excess that
// does not fit under the object moves outwards along a Euclidean distance
// transform from the contact (distance_transform.h), so rims are round.
//
// Dragging (paper 000, 3.4, second paragraph): the contact cells are taken from
// the side opposite the motion forwards, and each hands its material to its
// neighbours ahead (contact or free) and to free cells beside it; nothing goes
// backwards.
//
// In both, a free cell that the object overhangs takes no more than reaches
// the object's bottom and pushes its excess on to the free cells farther from
// the contact (backwards when dragging only if nothing else can take it). The
// bottom is a hard ceiling: material with nowhere to go under the object (a
// hole the contact encloses, the field's edge) is compressed, not stacked.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "terrain/grid.h"
#include "terrain/marks/ground_material.h"
#include "terrain/marks/object_bottom.h"

namespace drift::marks {

struct DisplacementReport {
  double collided = 0.0;      // sum of h' over the contact (m of height, times cell area = m3)
  double displaced = 0.0;     // sum of alpha h'
  double compressed = 0.0;    // sum of (1 - alpha) h'
  std::vector<int> contact;   // flat indices of the collided cells
  std::vector<int> received;  // flat indices of the free cells that took material
};

// Mud's heave band reaches kHeaveReach x heave x the footing's width: its
// smoothstep taper holds 90 % of the volume within 0.60 of its reach, where
// the linear taper it replaced held it within 0.68, so the band is 1.13
// times as long to stand as wide as before (a footing's width, heave 1).
inline constexpr double kHeaveReach = 1.13;

// heights: the whole field (m), updated in the bottom map's window.
// drag: the horizontal motion in cell space (any length), or none when pressing.
// disturbed (optional): accumulates |change| per cell. dx, dy: cell sizes (m).
DisplacementReport compress_and_displace(terrain::Grid<double>& heights, const BottomMap& bottom,
                                         const MaterialField& materials,
                                         const std::optional<Eigen::Vector2d>& drag,
                                         terrain::Grid<float>* disturbed = nullptr, double dx = 1.0,
                                         double dy = 1.0);

}  // namespace drift::marks
