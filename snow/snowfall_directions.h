// The directions snow falls from (paper 003, 2.1(2)): snow does not fall in
// straight lines; several shadow maps from directions jittered around the mean
// direction, each weighted by a normal distribution of its angle from the mean,
// give the probability that a point receives snow.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace drift::snow {

struct FallDirection {
  Eigen::Vector3d toward_source;  // unit; snow travels along -toward_source
  float weight = 1.0f;            // normalised: the weights of a set sum to 1 (in float, in order)
  double angle_rad = 0.0;         // angle from the mean direction
};

// `maps` directions around the mean. maps == 1 or spread == 0: the mean only
// (repeated). Otherwise an equal-area spiral over the cone of half-angle
// 2.5 x spread, rotated and jittered within its strata by `seed`, each weighted
// by exp(-angle^2 / (2 spread^2)): a quadrature of the Gaussian-weighted mean over
// directions. Deterministic for a seed. Throws drift::Error if a direction would
// fall less than 1 degree above the horizon.
std::vector<FallDirection> jittered_directions(double azimuth_deg, double elevation_deg,
                                               double spread_deg, int maps, std::uint64_t seed);

}  // namespace drift::snow
