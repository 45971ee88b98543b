// Exact Euclidean distance transform of a window of cells (Felzenszwalb &
// Huttenlocher 2012, "Distance transforms of sampled functions", Theory of
// Computing 8: the lower envelope of parabolas, one pass along columns and one
// along rows). Paper 000, 3.4 moves displaced material from the inside of the
// contact outwards along a distance transform; a Euclidean one (rather than the
// chessboard's squares) makes straight edges give even rims and round objects
// round ones (issue 32).
#pragma once

#include <vector>

namespace drift::marks {

// For each cell of a width x height window (row-major), the distance in
// metres (cells dx by dy) from its centre to the nearest source cell's centre;
// +inf when there is none. With `edge_is_source`, the ring of cells just
// outside the window counts as sources (the ground goes on there).
std::vector<double> euclidean_distance(const std::vector<char>& source, int width, int height,
                                       double dx, double dy, bool edge_is_source);

}  // namespace drift::marks
