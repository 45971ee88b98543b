#include "tests/soil/soil_fixtures.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "terrain/soil/top_surface.h"

namespace drift::soil::fixtures {

SoilSimulation column_scene(int n, int nz, double radius, double height, double voxel,
                            const SoilOptions& options) {
  terrain::Grid3Shape shape{n, n, nz, voxel, {0, 0, 0}};
  SoilState state(shape);
  Primitive column{PrimitiveKind::Cylinder,
                   Eigen::Vector3d(0.5 * n * voxel, 0.5 * n * voxel, 0.5 * height * voxel),
                   Eigen::Vector3d(radius * voxel, 0, 0.5 * height * voxel)};
  add_soil(state, {column}, Eigen::Vector3d::Zero());
  return SoilSimulation(std::move(state), {}, options);
}

int run_until_settled(SoilSimulation& sim, int max_steps, int window, float tolerance) {
  std::vector<float> before = sim.state().rho;
  for (int step = 1; step <= max_steps; ++step) {
    sim.step();
    if (step % window) continue;
    float change = 0;
    for (std::size_t i = 0; i < before.size(); ++i)
      change = std::max(change, std::abs(sim.state().rho[i] - before[i]));
    if (change <= tolerance) return step;
    before = sim.state().rho;
  }
  return max_steps;
}

PileTops pile_tops(const SoilState& s) {
  const auto& g = s.shape;
  PileTops p;
  p.nx = g.nx;
  p.ny = g.ny;
  p.top.resize(g.columns());
  double w = 0;
  for (int y = 0; y < g.ny; ++y)
    for (int x = 0; x < g.nx; ++x) {
      const float t = column_top(s, x, y);
      p.top[static_cast<std::size_t>(y) * g.nx + x] = t;
      p.peak = std::max(p.peak, t);
      p.cx += t * (x + 0.5);
      p.cy += t * (y + 0.5);
      w += t;
    }
  p.cx /= w;
  p.cy /= w;
  return p;
}

double PileTops::at(double x, double y) const {
  x -= 0.5;  // to column indices
  y -= 0.5;
  const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, nx - 2),
            y0 = std::clamp(static_cast<int>(std::floor(y)), 0, ny - 2);
  const double fx = std::clamp(x - x0, 0.0, 1.0), fy = std::clamp(y - y0, 0.0, 1.0);
  const auto& t = *this;
  return (1 - fy) * ((1 - fx) * t(x0, y0) + fx * t(x0 + 1, y0)) +
         fy * ((1 - fx) * t(x0, y0 + 1) + fx * t(x0 + 1, y0 + 1));
}

double radius_spread(const SoilState& s, double fraction, int directions) {
  const PileTops p = pile_tops(s);
  double lo = 1e9, hi = 0;
  for (int k = 0; k < directions; ++k) {
    const double a = 2 * M_PI * k / directions;
    double r = 0;
    while (r < p.nx && p.at(p.cx + r * std::cos(a), p.cy + r * std::sin(a)) > fraction * p.peak)
      r += 0.005;
    lo = std::min(lo, r), hi = std::max(hi, r);
  }
  return hi / lo - 1;
}

double pile_angle_deg(const SoilState& s, double* spread_deg) {
  const auto& g = s.shape;
  const PileTops p = pile_tops(s);
  const std::vector<float>& top = p.top;
  const float peak = p.peak;
  const double cx = p.cx, cy = p.cy;
  // Per sector of 45 degrees and overall: fit top = a - b r.
  double sums[9][5] = {};  // n, sr, st, srr, srt
  for (int y = 0; y < g.ny; ++y)
    for (int x = 0; x < g.nx; ++x) {
      const float t = top[static_cast<std::size_t>(y) * g.nx + x];
      if (t < 0.2f * peak || t > 0.8f * peak) continue;
      const double dx = x + 0.5 - cx, dy = y + 0.5 - cy, r = std::hypot(dx, dy);
      int sector = static_cast<int>(std::floor((std::atan2(dy, dx) + M_PI) / (M_PI / 4))) % 8;
      for (int k : {sector, 8}) {
        sums[k][0] += 1;
        sums[k][1] += r;
        sums[k][2] += t;
        sums[k][3] += r * r;
        sums[k][4] += r * t;
      }
    }
  auto angle = [&](int k) {
    const double* q = sums[k];
    const double b = (q[0] * q[4] - q[1] * q[2]) / (q[0] * q[3] - q[1] * q[1]);
    return std::atan(-b) * 180.0 / M_PI;
  };
  if (spread_deg) {
    double lo = 1e9, hi = -1e9;
    for (int k = 0; k < 8; ++k) {
      if (sums[k][0] < 3) continue;
      lo = std::min(lo, angle(k));
      hi = std::max(hi, angle(k));
    }
    *spread_deg = hi - lo;
  }
  return angle(8);
}

std::uint64_t state_hash(const SoilState& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (const auto* f : {&s.rho, &s.ux, &s.uy, &s.uz, &s.fx, &s.fy, &s.fz})
    for (float v : *f) {
      std::uint32_t bits;
      std::memcpy(&bits, &v, 4);
      for (int b = 0; b < 4; ++b) h = (h ^ ((bits >> (8 * b)) & 0xff)) * 1099511628211ull;
    }
  return h;
}

float max_fill(const SoilState& s) {
  float m = 0;
  for (std::size_t i = 0; i < s.size(); ++i) m = std::max(m, s.rho[i] + s.psi[i]);
  return m;
}

float min_rho(const SoilState& s) { return *std::min_element(s.rho.begin(), s.rho.end()); }

}  // namespace drift::soil::fixtures

namespace drift::soil::fixtures {

namespace {
// An empty scenario on an n^3 grid of 0.1 m voxels.
SoilScenario cube_scenario(const char* name, int n, const SoilOptions& options) {
  SoilScenario sc;
  sc.name = name;
  sc.shape = {n, n, n, 0.1, {0, 0, 0}};
  sc.options = options;
  return sc;
}
}  // namespace

SoilScenario push_scenario(int n, const SoilOptions& options) {
  SoilScenario sc = cube_scenario("push", n, options);
  const double L = n * sc.shape.voxel_size;
  sc.soil.push_back(
      {"ground",
       {{PrimitiveKind::Cuboid, {L / 2, L / 2, 0.125 * L}, {L / 2, L / 2, 0.125 * L}}},
       {0, 0, 0},
       false,
       {}});
  RigidObject block;
  block.name = "blade";
  block.primitives = {{PrimitiveKind::Cuboid, {0, 0, 0}, {0.05 * L, 0.3 * L, 0.15 * L}}};
  const Eigen::Vector3d start(0.1 * L, 0.5 * L, 0.32 * L), end(0.7 * L, 0.5 * L, 0.32 * L);
  block.path = {{0.0, start}, {(end - start).norm() / 1.5, end}};
  sc.bodies.push_back(block);
  return sc;
}

SoilScenario pour_block_scenario(int n, const SoilOptions& options) {
  SoilScenario sc = cube_scenario("pour_block", n, options);
  const double L = n * sc.shape.voxel_size;
  sc.bodies.push_back({"block",
                       {{PrimitiveKind::Cuboid, {0, 0, 0}, {0.12 * L, 0.12 * L, 0.15 * L}}},
                       {{0.0, {0.5 * L, 0.5 * L, 0.15 * L}}},
                       {0, 0, 0},
                       {}});
  sc.soil.push_back({"column",
                     {{PrimitiveKind::Cylinder, {0, 0, 0}, {0.18 * L, 0, 0.2 * L}}},
                     {0.5 * L, 0.5 * L, 0.72 * L},
                     false,
                     {}});
  return sc;
}

}  // namespace drift::soil::fixtures

namespace drift::soil::fixtures {
float column_top_of(const SoilState& state, int x, int y) { return column_top(state, x, y); }
}  // namespace drift::soil::fixtures
