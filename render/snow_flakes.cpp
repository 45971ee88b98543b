#include "render/snow_flakes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "render/procedural_noise.h"
#include "terrain/hash.h"

namespace drift::render {

namespace {

// Radii uniform in (1 +- kRadiusSpread) x kFlakeRadius.
constexpr double kRadiusSpread = 0.5;
constexpr double kMaxRadius = (1.0 + kRadiusSpread) * kFlakeRadius;
// Flakes are drawn per square cell one largest radius wide: a flake that
// covers a point has its centre in the point's cell or one of the 8 around.
constexpr double kCell = kMaxRadius;
// Mean disc area, pi E[r^2] = pi rm^2 (1 + s^2 / 3) for r uniform in rm (1 +- s).
constexpr double kMeanArea =
    std::numbers::pi * kFlakeRadius * kFlakeRadius * (1.0 + kRadiusSpread * kRadiusSpread / 3.0);
// Flakes landing in a cell per unit of tau: an intensity of 1 / kMeanArea per
// square metre and unit of tau covers the fraction 1 - exp(-tau).
constexpr double kFlakesPerTau = kCell * kCell / kMeanArea;
// Coverage from which every point counts as covered: tau stays below 6.9, so
// an uncovered point visits about 40 flakes at most; the area error is < 1e-3.
constexpr float kFullCover = 0.999f;
// Footprint (metres) beyond which flakes are replaced by their mean: four
// mean diameters.
constexpr double kFlakeFade = 8.0 * kFlakeRadius;
// Contrast of the clumps: m = tanh(kClumpContrast x unit-variance noise).
constexpr float kClumpContrast = 1.5f;

// Seeds of the three projection planes and of the clumps.
constexpr unsigned kPlaneSeeds[3] = {0x5f1a7e0u, 0x5f1a7e1u, 0x5f1a7e2u};
constexpr std::uint64_t kClumpSeed = 0xc1a3b5ULL;

// Sequential random numbers keyed by a cell (counter-based: terrain/hash.h).
struct CellRandom {
  std::uint64_t state;
  double next() {
    state = terrain::mix64(state);
    return terrain::unit_double(state);
  }
};

// True if a flake of cell (i, j) that landed by `tau` covers (u, v). The
// cell's flakes come in landing order: exponential gaps of rate kFlakesPerTau
// (a Poisson process in tau), each with a uniform centre and radius.
bool cell_covers(std::int64_t i, std::int64_t j, double u, double v, double tau,
                 std::uint64_t seed) {
  CellRandom rng{terrain::mix64(seed ^ (static_cast<std::uint64_t>(i) * 0xd1b54a32d192ed03ULL) ^
                                (static_cast<std::uint64_t>(j) * 0x9e3779b97f4a7c15ULL))};
  double landed = 0.0;
  for (;;) {
    landed -= std::log1p(-rng.next()) / kFlakesPerTau;
    if (landed > tau) return false;
    const double cx = (static_cast<double>(i) + rng.next()) * kCell;
    const double cy = (static_cast<double>(j) + rng.next()) * kCell;
    const double r = kFlakeRadius * (1.0 + kRadiusSpread * (2.0 * rng.next() - 1.0));
    if ((cx - u) * (cx - u) + (cy - v) * (cy - v) < r * r) return true;
  }
}

// The point's coordinates in the plane that faces `normal` most squarely, and
// that plane's seed.
struct PlanePoint {
  double u, v;
  unsigned seed;
};
PlanePoint project(const Eigen::Vector3d& p, const Eigen::Vector3f& normal) {
  const Eigen::Vector3f a = normal.cwiseAbs();
  if (a.z() >= a.x() && a.z() >= a.y()) return {p.x(), p.y(), kPlaneSeeds[2]};
  if (a.x() >= a.y()) return {p.y(), p.z(), kPlaneSeeds[0]};
  return {p.x(), p.z(), kPlaneSeeds[1]};
}

}  // namespace

bool flake_covers(double u, double v, float coverage, unsigned seed) {
  if (!(coverage > 0.0f)) return false;
  if (coverage >= kFullCover) return true;
  const double tau = -std::log1p(-static_cast<double>(coverage));
  const double fu = std::floor(u / kCell), fv = std::floor(v / kCell);
  const auto i0 = static_cast<std::int64_t>(fu), j0 = static_cast<std::int64_t>(fv);
  const double du = u - fu * kCell, dv = v - fv * kCell;  // within the cell, [0, kCell)
  for (int dj = -1; dj <= 1; ++dj) {
    // Distance from (u, v) to the neighbour cell: beyond the largest radius
    // none of its flakes can reach.
    const double gap_v = dj < 0 ? dv : dj > 0 ? kCell - dv : 0.0;
    for (int di = -1; di <= 1; ++di) {
      const double gap_u = di < 0 ? du : di > 0 ? kCell - du : 0.0;
      if (gap_u * gap_u + gap_v * gap_v >= kMaxRadius * kMaxRadius) continue;
      if (cell_covers(i0 + di, j0 + dj, u, v, tau, seed)) return true;
    }
  }
  return false;
}

float clumped_coverage(double u, double v, float coverage, unsigned seed, double footprint) {
  if (!(coverage > 0.0f) || !(coverage < 1.0f) || footprint >= kClumpScale) return coverage;
  // 3 octaves of equal amplitude: a sum of unit standard deviation.
  const Octaves octaves{kClumpScale, kClumpScale / 4.0, kClumpSeed + seed};
  const float amplitude = 1.0f / (std::sqrt(3.0f) * kNoiseStd);
  const float n = filtered_noise(u, v, octaves, amplitude, 0.0f, footprint).value;
  // tanh is odd and the noise symmetric about 0, so m has mean 0; |m| < 1
  // and min(c, 1 - c) keep the local coverage inside [0, 1].
  const float m = std::tanh(kClumpContrast * n);
  return coverage + kFlakeClumping * std::min(coverage, 1.0f - coverage) * m;
}

namespace {

// The pattern at plane point q for a round footprint `footprint` wide.
float cover_at(const PlanePoint& q, float coverage, double footprint) {
  const float local = clumped_coverage(q.u, q.v, coverage, q.seed, footprint);
  // Flakes are kept whole while the footprint is below two diameters and
  // gone above four, where it holds a dozen flake areas and their covered
  // share strays from its mean by about a fifth of a flake's contrast (less
  // than a few point samples would); the blend is procedural_noise.h's.
  const float keep = footprint > 0.0
                         ? static_cast<float>(std::clamp(kFlakeFade / footprint - 1.0, 0.0, 1.0))
                         : 1.0f;
  if (keep <= 0.0f) return local;
  const float flakes = flake_covers(q.u, q.v, local, q.seed) ? 1.0f : 0.0f;
  return local + keep * (flakes - local);
}

// How many times longer than wide the footprint is on the surface (1 seen
// head-on or with no ray), and the unit direction of its long axis.
double stretch(const Eigen::Vector3f& normal, const Eigen::Vector3f& ray, Eigen::Vector3d& along) {
  const Eigen::Vector3f n = normal.normalized();
  const float cos_in = std::abs(ray.dot(n));
  const Eigen::Vector3f t = ray - ray.dot(n) * n;  // the ray projected onto the surface
  if (!(t.norm() > 1e-6f) || !(cos_in > 0.0f)) return 1.0;
  along = t.normalized().cast<double>();
  return std::min(1.0 / cos_in, 1e6);
}

}  // namespace

float flake_cover(const Eigen::Vector3d& p, const Eigen::Vector3f& normal, float coverage,
                  double footprint, const Eigen::Vector3f& ray) {
  if (!(coverage > 0.0f)) return 0.0f;
  if (!(coverage < 1.0f)) return 1.0f;
  Eigen::Vector3d along = Eigen::Vector3d::Zero();
  const double s = footprint > 0.0 ? stretch(normal, ray, along) : 1.0;
  if (s < 1.5) return cover_at(project(p, normal), coverage, footprint);
  // Probes spaced evenly along the long axis, each as wide as the footprint
  // (wider when kMaxProbes do not reach along it).
  const double length = footprint * s;
  const int probes = std::min(static_cast<int>(std::ceil(s)), kMaxProbes);
  const double width = std::max(footprint, length / probes);
  float sum = 0.0f;
  for (int k = 0; k < probes; ++k) {
    const double offset = ((k + 0.5) / probes - 0.5) * length;
    sum += cover_at(project(p + offset * along, normal), coverage, width);
  }
  return sum / static_cast<float>(probes);
}

}  // namespace drift::render
