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
// jittered by noise of the ground position (raggedness).
#pragma once

#include <cstddef>
#include <cstdint>

#include "terrain/grid.h"

namespace drift::render {

// Height minus the mean height of the square window of half-width
// `radius_metres` around each cell (clipped at the edges; NaN cells ignored
// and kept NaN), in the DEM's georeference. Summed-area table, O(cells).
terrain::HeightField topographic_position(const terrain::HeightField& dem, double radius_metres);

// Smooth noise of the ground position (wavelengths 800 m to 25 m, standard
// deviation 1/2, within about +-1): a rule's altitude bounds move by its
// `altitude_jitter` times this, so that a tree line or a snow line follows
// the terrain raggedly. One field for all rules, so zones shift together
// (a warm, sheltered slope lifts the forest line and the meadows alike).
// A `footprint` (metres) fades the octaves it covers, as the ground detail's
// (render/procedural_noise.h): a far or bounced ray's rules read the jitter
// it can resolve, for a quarter to a half of the noise's cost.
float raggedness(double x, double y, double footprint = 0.0);

// Clumps: where a sparse plant cover grows as separate bushes or groups of
// them (autumn rowan and birch scrub), a rule covers `cover` of the ground in
// blobs about `size` metres across instead of tinting all of it. The mask
// is 1 inside a clump and 0 between, with soft edges; the ray's footprint
// fades it into its mean (`cover`) once the clumps are smaller than a
// footprint, as the ground detail's octaves fade, so distant scrub keeps its
// share of the colour and does not shimmer. `seed` tells rules apart.
float clump_mask(double x, double y, float size, float cover, std::uint64_t seed, double footprint);

}  // namespace drift::render
