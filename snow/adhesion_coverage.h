// How much of a surface looks white (paper 003, 2.1(4) and 2.3(5)).
//
// Thin snow: a layer thinner than `thin_depth` reads as scattered flakes, not a
// film; coverage = depth / thin_depth below it, 1 above.
//
// Sparse adhesion: steep and overhanging faces hold no snow depth but flakes stick
// to them. The paper's two conditions: the larger the angle between the face and
// the ground, and the larger the angle between the face and the snowfall (the
// more it faces the snow), the more sticks. Here
//   adhesion = strength x steep(phi) x facing x (1 - exp(-amount / adhesion_depth)),
// phi the angle of the normal from up, steep rising linearly from 0 at min_slope
// to 1 at 90 degrees and staying 1 on overhangs, facing the weighted mean over
// the jittered directions of lit x max(0, n . d) (so faces in the lee or under a
// roof get none), the last factor saturating with the amount that fell.
#pragma once

#include <Eigen/Core>

namespace drift::snow {

struct CoverageOptions {
  double thin_depth = 0.03;        // m: snow thinner than this is a speckle, (0, 10]
  double adhesion = 0.6;           // coverage of stuck flakes on a wall facing the snow, [0, 1]
  double adhesion_min_slope = 60;  // degrees from horizontal where flakes start to stick, [0, 90)
  double adhesion_depth = 0.05;    // m of snowfall that makes 63 % of the full adhesion, > 0
};

// Coverage from depth alone (thin-snow speckle).
double thin_coverage(double depth, const CoverageOptions& o);

// Adhesion of a face with unit normal n; facing = weighted lit x (n . d) in [0, 1];
// amount = rate x hours (m).
double adhesion_coverage(const Eigen::Vector3d& n, double facing, double amount,
                         const CoverageOptions& o);

}  // namespace drift::snow
