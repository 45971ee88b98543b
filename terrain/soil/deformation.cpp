#include "terrain/soil/deformation.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "terrain/soil/transport.h"

namespace drift::soil {

namespace {
constexpr float kCollided = 1e-6f;  // rho + psi - 1 above which a voxel is collided
constexpr float kSolid = 1.0f - 1e-6f;
}  // namespace

void apply_forces(SoilState& s, const std::vector<BodyMotion>& bodies) {
  const terrain::Grid3Shape& g = s.shape;
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x)
      for (int z = 0; z < g.nz; ++z) {
        const std::size_t i = g.index(x, y, z);
        if (s.rho[i] + s.psi[i] <= 1.0f + kCollided) {
          s.fx[i] = s.fy[i] = s.fz[i] = 0;
          continue;
        }
        if (s.psi[i] <= 0) continue;  // eq. 33, second case: f kept
        Eigen::Vector3d v(0, 0, 0);
        for (const BodyMotion& b : bodies)
          if (x >= b.box.lo.x() && x < b.box.hi.x() && y >= b.box.lo.y() && y < b.box.hi.y() &&
              z >= b.box.lo.z() && z < b.box.hi.z()) {
            v = b.velocity;
            if (b.spin != Eigen::Vector3d::Zero()) {
              const Eigen::Vector3d p =
                  g.origin + g.voxel_size * Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5);
              v += b.spin.cross(p - b.pivot);
            }
            break;
          }
        const double len = v.norm();
        if (len > 0)
          v /= len;
        else
          v = Eigen::Vector3d::UnitZ();
        s.fx[i] = static_cast<float>(v.x());
        s.fy[i] = static_cast<float>(v.y());
        s.fz[i] = static_cast<float>(v.z());
      }
  });
}

detail::Ranges propagate_forces(SoilState& s) {
  const terrain::Grid3Shape& g = s.shape;
  std::vector<float>& moving = s.back.moving;
  // The collided soil that moves, and per column the range holding it.
  detail::Ranges senders(g.columns(), {g.nz, -1});
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x) {
      auto& r = senders[static_cast<std::size_t>(y) * g.nx + x];
      for (int z = 0; z < g.nz; ++z) {
        const std::size_t i = g.index(x, y, z);
        const float e = s.rho[i] + s.psi[i] - 1.0f;
        const bool pushed = e > kCollided && (s.fx[i] != 0 || s.fy[i] != 0 || s.fz[i] != 0);
        moving[i] = pushed ? std::min(e, s.rho[i]) : 0.0f;
        if (!pushed) continue;
        r.first = std::min(r.first, z);
        r.second = z;
      }
    }
  });
  if (std::all_of(senders.begin(), senders.end(), [](const auto& r) { return r.first > r.second; }))
    return senders;
  const float *fx = s.fx.data(), *fy = s.fy.data(), *fz = s.fz.data(), *psi = s.psi.data();
  auto disp = [=](std::size_t i) {  // eq. 34: f over its largest component
    const float m = std::max(std::abs(fx[i]), std::max(std::abs(fy[i]), std::abs(fz[i])));
    return m > 0 ? detail::D3{fx[i] / m, fy[i] / m, fz[i] / m} : detail::D3{};
  };
  auto open = [=](std::size_t i) { return psi[i] < kSolid; };
  const detail::Carried carried{
      {s.ux.data(), s.uy.data(), s.uz.data()}, {fx, fy, fz}, s.wet.data()};
  return detail::transport(
      g, moving.data(), senders, open, disp, carried, true,
      [&](std::size_t i, const detail::Gathered& r) {
        const float kept = s.rho[i] - moving[i], now = kept + r.amount;
        const float inv = detail::weight_inverse(now);
        s.back.rho[i] = now;
        s.back.ux[i] = (kept * s.ux[i] + r.u[0]) * inv;
        s.back.uy[i] = (kept * s.uy[i] + r.u[1]) * inv;
        s.back.uz[i] = (kept * s.uz[i] + r.u[2]) * inv;
        s.back.wet[i] =
            now > 1e-30f ? std::clamp((kept * s.wet[i] + r.m) * inv, 0.0f, 1.0f) : s.wet[i];
        const bool collided = now + s.psi[i] > 1.0f + kCollided && r.amount > 0;
        const float fin = collided ? detail::weight_inverse(r.amount) : 0.0f;  // eq. 35
        s.back.fx[i] = r.f[0] * fin;
        s.back.fy[i] = r.f[1] * fin;
        s.back.fz[i] = r.f[2] * fin;
      },
      false, [](std::size_t, float) {}, [&](std::size_t i) { copy_back(s, i); });
}

}  // namespace drift::soil
