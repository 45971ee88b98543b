#include "terrain/soil/simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "terrain/error.h"
#include "terrain/soil/deformation.h"
#include "terrain/soil/drainage.h"
#include "terrain/soil/soil_parameters.h"

namespace drift::soil {

namespace {

// Marks the columns of a body's voxel box, widened by one, as dirty.
void mark_box(const VoxelBox& box, ColumnMask& dirty, const terrain::Grid3Shape& g) {
  for (int y = std::max(0, box.lo.y() - 1); y < std::min(g.ny, box.hi.y() + 1); ++y)
    for (int x = std::max(0, box.lo.x() - 1); x < std::min(g.nx, box.hi.x() + 1); ++x)
      dirty[static_cast<std::size_t>(y) * g.nx + x] = 1;
}

}  // namespace

void SoilOptions::validate() const {
  for (const SoilParameter& p : soil_parameters()) p.require(*this);
}

SoilSimulation::SoilSimulation(SoilState state, std::vector<RigidObject> bodies,
                               const SoilOptions& options)
    : state_(std::move(state)), options_(options), slippage_(state_.shape) {
  options_.validate();
  for (RigidObject& b : bodies) {
    validate(b, "body");
    if (b.moves()) {
      bodies_.push_back(std::move(b));
    } else {
      add_coverage(placed(b, 0.0), state_.shape, state_.psi_static);
    }
  }
  rebuild_collision_field();
}

void SoilSimulation::rebuild_collision_field() {
  state_.psi = state_.psi_static;
  coverage_.resize(bodies_.size());
  for (std::size_t k = 0; k < bodies_.size(); ++k) add_body_coverage(bodies_[k], coverage_[k]);
}

void SoilSimulation::add_body_coverage(const RigidObject& body, CoverageCache& c) {
  const terrain::Grid3Shape& g = state_.shape;
  const PlacedSolid solid = placed(body, time_);
  // An axis-aligned body of primitives has its exact share in closed form
  // (0.4 ms a step for the push's blade): nothing to keep.
  if (!solid.mesh && !solid.pose.rotated()) {
    add_coverage(solid, g, state_.psi);
    return;
  }
  const VoxelBox box = voxel_box(solid, g);
  // A box that touches the grid's side may have been clipped.
  auto whole = [&g](const VoxelBox& b) {
    return (b.lo.array() > 0).all() && b.hi.x() < g.nx && b.hi.y() < g.ny && b.hi.z() < g.nz;
  };
  Eigen::Vector3i shift(0, 0, 0);
  bool reuse = false;
  if (c.valid && solid.pose.rotation == c.pose.rotation && !box.empty()) {
    const Eigen::Vector3d d = (solid.pose.position - c.pose.position) / g.voxel_size;
    const Eigen::Vector3d r = d.array().round();
    if ((d - r).cwiseAbs().maxCoeff() < 1e-6) {
      shift = r.cast<int>();
      reuse = box.lo == c.box.lo + shift && box.hi == c.box.hi + shift &&
              (shift.isZero() || (whole(box) && whole(c.box)));
    }
  }
  const Eigen::Vector3i n = c.box.hi - c.box.lo;
  if (!reuse) {
    c = CoverageCache{true, solid.pose, box, {}};
    if (box.empty()) return;
    const Eigen::Vector3i m = box.hi - box.lo;
    c.share.assign(static_cast<std::size_t>(m.x()) * m.y() * m.z(), 0.0f);
    for_each_covered_voxel(solid, g, [&c, &g, &m](std::size_t i, float share) {
      const int z = static_cast<int>(i % g.nz), col = static_cast<int>(i / g.nz);
      const int x = col % g.nx - c.box.lo.x(), y = col / g.nx - c.box.lo.y();
      c.share[(static_cast<std::size_t>(y) * m.x() + x) * m.z() + (z - c.box.lo.z())] = share;
    });
    return add_body_coverage(body, c);  // now a reuse with no shift
  }
  for (int y = 0; y < n.y(); ++y)
    for (int x = 0; x < n.x(); ++x)
      for (int z = 0; z < n.z(); ++z) {
        const float share = c.share[(static_cast<std::size_t>(y) * n.x() + x) * n.z() + z];
        if (share <= 0) continue;
        float& psi = state_.psi[g.index(box.lo.x() + x, box.lo.y() + y, box.lo.z() + z)];
        psi = std::min(1.0f, psi + share);
      }
}

void SoilSimulation::step() {
  const double dt = options_.dt;
  // Move the bodies to the end of the step; their velocity over it (a
  // turning body's differs point by point) drives eq. 33.
  std::vector<BodyMotion> motion;
  for (const RigidObject& b : bodies_) {
    const double mid = time_ + 0.5 * dt;
    motion.push_back({voxel_box(placed(b, time_ + dt), state_.shape), b.velocity(mid),
                      b.angular_velocity(mid), b.position(mid)});
  }
  time_ += dt;
  rebuild_collision_field();

  // Overflow can only arise where soil moved or a body is: mark those columns.
  ColumnMask dirty(state_.shape.columns(), 0);
  auto mark = [&](const detail::Ranges& r) {
    for (std::size_t c = 0; c < r.size(); ++c) dirty[c] |= r[c].first <= r[c].second;
  };
  for (const BodyMotion& m : motion) mark_box(m.box, dirty, state_.shape);

  apply_forces(state_, motion);
  detail::Ranges reach;
  for (int i = 0; i < options_.propagation_iterations; ++i) {
    // After the first iteration only what the last one reached can move.
    reach = propagate_forces(state_, i == 0 ? nullptr : &reach);
    mark(reach);
  }

  mark(advect(state_, dt));
  resolve_overflow(state_, options_.overflow, options_.overflow_passes, &dirty);
  if (options_.settle) settle_overflow(state_, &dirty);

  apply_gravity(state_, options_.gravity, dt);
  if (options_.slippage) {
    slippage_.step(state_, options_.soil, options_.gravity, dt);
    if (options_.settle && slippage_.any_overfilled())
      settle_overflow(state_, &slippage_.overfilled());
  }
  // Soil resting on a moving body rides with it (issue 33, item 4).
  ColumnMask riding(state_.shape.columns(), 0);
  carry_riding_soil(state_, motion, dt, riding);
  if (options_.settle && std::find(riding.begin(), riding.end(), 1) != riding.end())
    settle_overflow(state_, &riding);
  // Water drains down and evaporates from the top (issue 33, item 3).
  drain_moisture(state_, options_.soil, dt);
  ++steps_;
}

SoilRunStats run_soil(SoilSimulation& sim, const SoilRunOptions& o, const ProgressFn& progress) {
  SoilRunStats stats;
  stats.mass_before = sim.state().mass();
  stats.water_before = sim.state().water();
  const auto t0 = std::chrono::steady_clock::now();
  if (!progress(0.0, "simulating")) throw Cancelled();
  for (int step = 1; step <= o.steps; ++step) {
    sim.step();
    if (o.frame && o.frame_every > 0 && step % o.frame_every == 0) o.frame(sim, step);
    if (step < o.steps && !progress(static_cast<double>(step) / o.steps, "simulating"))
      throw Cancelled();
  }
  stats.steps = o.steps;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  stats.mass_after = sim.state().mass();
  stats.water_after = sim.state().water();
  if (!progress(1.0, "done")) throw Cancelled();
  return stats;
}

void add_soil(SoilState& s, const std::vector<Primitive>& prims, const Eigen::Vector3d& pos,
              double moisture) {
  const float m = static_cast<float>(std::clamp(moisture, 0.0, 1.0));
  for_each_covered_voxel(prims, pos, s.shape, [&s, m](std::size_t i, float c) {
    const float room = std::max(0.0f, 1.0f - std::max(s.psi_static[i], s.psi[i]) - s.rho[i]);
    const float put = std::min(room, c);
    if (put <= 0) return;
    s.wet[i] = mix_moisture(s.rho[i], s.wet[i], put, m);
    s.rho[i] += put;
  });
}

}  // namespace drift::soil
