// Snow that covers part of a surface, shown as flakes (paper 003, 2.1(4)
// and 2.3(5); docs/snowfall.md, Thin snow and stuck flakes): the start of a
// snowfall and the flakes stuck to steep faces are "a texture of sparsely
// attached flakes", not a pale film. The snow stages give a coverage c in
// [0, 1] (snow/adhesion_coverage.h); here c becomes a deterministic world-space
// pattern whose covered area fraction is c.
//
// The pattern is a Boolean model (Chiu, Stoyan, Kendall & Mecke 2013,
// "Stochastic Geometry and its Applications", ch. 3: discs of a Poisson
// process cover the fraction 1 - exp(-intensity x mean disc area)): flakes are discs of random
// radius landing at random places and "times" tau, as many per area and per unit of tau as make the
// expected covered fraction at tau exactly 1 - exp(-tau). A point is covered at
// coverage c when a flake that landed before tau(c) = -ln(1 - c) covers it, so
// the covered fraction is c, and a growing coverage only adds flakes (a
// snowfall's start grows, it does not reshuffle). Flakes gather into clumps:
// the local coverage is c + kClumping min(c, 1 - c) m(x), m a bounded odd
// function of zero-mean noise (decimetre octaves), which stays in [0, 1] and
// keeps the mean c.
//
// Filtering (the ripples' LEAN filtering and render/procedural_noise.h are the
// model): the pattern's scales are faded by the ray's footprint as a mip-map
// is. Flakes are kept whole while the footprint is below two flake diameters
// and are gone above four, replaced by their mean (the local coverage); the
// clumps' octaves fade likewise. Far away the value is c exactly (no shimmer,
// no aliasing, the mean kept at every footprint).
//
// At grazing angles the footprint on the surface is an ellipse, `footprint`
// wide across the ray and footprint / cos(incidence) long along it (the ray
// cone cut by the surface, as ray-differential texture filtering has it;
// Igehy 1999): the pattern is then the mean of probes spaced along the long
// axis, each filtered at the footprint's width (or at the long axis over
// kMaxProbes, when more would be needed), as anisotropic texture filtering
// takes several probes along the axis. Each probe keeps the mean, so the
// average stays the coverage, and the flakes a long footprint spans are
// averaged, not point-sampled (no shimmer).
//
// On steep faces (stuck flakes) the pattern lies in the plane that faces the
// surface most squarely (x-y, y-z or x-z by the normal's largest component),
// so flakes stay round on walls; the planes use their own seeds.
#pragma once

#include <Eigen/Core>

namespace drift::render {

// Mean flake radius (metres), a chosen value: fresh snowflakes and the clumps
// they make on landing are millimetres to about a centimetre across. Radii are
// uniform in [0.5, 1.5] x this.
constexpr double kFlakeRadius = 0.004;
// Strength of the clumping in [0, 1] (0: flakes independent of each other).
constexpr float kFlakeClumping = 0.7f;
// Largest wavelength of the clumps (metres); octaves down to a quarter of it.
constexpr double kClumpScale = 0.32;
// Where flakes lie (coverage below 1) their snow is at least this deep (metres) for its
// translucency (render/surface.h: 1 cm over black rock reflects 0.79 where
// deep snow reflects 0.90), so stuck flakes on a wall with no depth read white.
constexpr float kFlakeDepth = 0.01f;

// The share of a footprint `footprint` metres wide around world point `p`
// (CRS metres, rendered heights) on a surface of unit normal `normal` that
// flakes cover, for a coverage c: 0 or 1 where flakes are resolved (footprint
// below 2 diameters), the local coverage where it spans many (above 4), c
// exactly beyond the clumps' scale.
// 0 for c <= 0, 1 for c >= 1.
// `ray` (unit; zero: seen head-on) is the ray's direction: the footprint
// stretches along it at grazing angles.
float flake_cover(const Eigen::Vector3d& p, const Eigen::Vector3f& normal, float coverage,
                  double footprint, const Eigen::Vector3f& ray = Eigen::Vector3f::Zero());

// Most probes along a stretched footprint.
constexpr int kMaxProbes = 8;

// The pattern's parts, for tests: whether flakes landed by tau(c) cover point
// (u, v) of a plane with seed `seed` (no clumping, no filtering) ...
bool flake_covers(double u, double v, float coverage, unsigned seed);
// ... and the clumped local coverage at (u, v) for a footprint.
float clumped_coverage(double u, double v, float coverage, unsigned seed, double footprint);

}  // namespace drift::render
