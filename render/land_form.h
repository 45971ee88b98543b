// Where on a mountain a point lies, for land-class rules beyond altitude and
// slope: the topographic position index (TPI, Weiss 2001, "Topographic
// position and landforms analysis", ESRI User Conference; Guisan et al. 1999,
// Plant Ecology 143, 107-122) is the height above the mean of the ground
// within a radius: positive on ridges and spurs, negative in gullies and
// hollows. In the Northern Alps it is what sorts the alpine belt: Pinus
// pumila on convex, wind-blown ridges, Erman's birch and late snow in concave
// gullies (Wardle 1977, Arctic and Alpine Research 9(3), 249-258), snow
// patches lasting into autumn in cirques and gullies (Higuchi & Iozawa 1971,
// "Atlas of perennial snow patches in central Japan", Nagoya University).
// Zone edges are ragged in nature: a rule's altitude bounds can be
// jittered by noise of the ground position (ragged_altitude).
#pragma once

#include <cstddef>

#include "terrain/grid.h"

namespace drift::render {

// Height minus the mean height of the square window of half-width
// `radius_metres` around each cell (clipped at the edges; NaN cells ignored
// and kept NaN), in the DEM's georeference. Summed-area table, O(cells).
terrain::HeightField topographic_position(const terrain::HeightField& dem, double radius_metres);

// `altitude` moved by up to about +-`jitter` metres by smooth noise of the
// ground position (wavelengths 800 m to 25 m), different for each `rule`,
// so that a tree line or a snow line follows the terrain raggedly.
float ragged_altitude(float altitude, float jitter, double x, double y, std::size_t rule);

}  // namespace drift::render
