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
          // Stored only where f is set: most voxels hold none, and writing
          // zeros over the whole grid every step dirtied 3 MB at 64^3.
          if (s.fx[i] != 0 || s.fy[i] != 0 || s.fz[i] != 0) s.fx[i] = s.fy[i] = s.fz[i] = 0;
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

detail::Ranges propagate_forces(SoilState& s, const detail::Ranges* scan) {
  const terrain::Grid3Shape& g = s.shape;
  std::vector<float>& moving = s.back.moving;
  // The collided soil that moves, and per column the range holding it.
  detail::Ranges senders(g.columns(), {g.nz, -1});
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x) {
      const std::size_t c = static_cast<std::size_t>(y) * g.nx + x;
      auto& r = senders[c];
      const int lo = scan ? (*scan)[c].first : 0, hi = scan ? (*scan)[c].second : g.nz - 1;
      for (int z = lo; z <= hi; ++z) {
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

namespace drift::soil {

void carry_riding_soil(SoilState& s, const std::vector<BodyMotion>& bodies, double dt,
                       std::vector<std::uint8_t>& touched) {
  const terrain::Grid3Shape& g = s.shape;
  struct Parcel {
    double x, y;  // where its voxel's centre goes, in voxels
    int z;
    float amount, wet;
  };
  std::vector<Parcel> parcels;
  for (const BodyMotion& b : bodies) {
    if (b.velocity.head<2>().isZero() && b.spin.isZero()) continue;
    parcels.clear();
    for (int y = std::max(0, b.box.lo.y()); y < std::min(g.ny, b.box.hi.y()); ++y)
      for (int x = std::max(0, b.box.lo.x()); x < std::min(g.nx, b.box.hi.x()); ++x) {
        // The body's top voxel in this column: held by a moving body.
        int top = -1;
        for (int z = std::min(g.nz, b.box.hi.z()) - 1; z >= std::max(0, b.box.lo.z()); --z) {
          const std::size_t i = g.index(x, y, z);
          if (s.psi[i] - s.psi_static[i] >= 0.5f) {
            top = z;
            break;
          }
        }
        if (top < 0 || top + 1 >= g.nz) continue;
        const Eigen::Vector3d contact =
            g.origin + g.voxel_size * Eigen::Vector3d(x + 0.5, y + 0.5, top + 1.0);
        const Eigen::Vector3d v = b.velocity + b.spin.cross(contact - b.pivot);
        const double dx = std::clamp(v.x() * dt / g.voxel_size, -1.0, 1.0),
                     dy = std::clamp(v.y() * dt / g.voxel_size, -1.0, 1.0);
        if (dx == 0 && dy == 0) continue;
        for (int z = top + 1; z < g.nz; ++z) {
          const std::size_t i = g.index(x, y, z);
          if (s.rho[i] <= 0 || s.psi[i] >= 0.5f) break;
          parcels.push_back({x + dx, y + dy, z, s.rho[i], s.wet[i]});
          s.rho[i] = 0;
        }
      }
    for (const Parcel& p : parcels) {
      const int x0 = static_cast<int>(std::floor(p.x)), y0 = static_cast<int>(std::floor(p.y));
      const double fx = p.x - x0, fy = p.y - y0;
      // Weights of the four columns; a column off the grid gives its share
      // back to the nearest one on it.
      for (int k = 0; k < 4; ++k) {
        const double w = (k & 1 ? fx : 1 - fx) * (k & 2 ? fy : 1 - fy);
        if (w <= 0) continue;
        const int x = std::clamp(x0 + (k & 1), 0, g.nx - 1),
                  y = std::clamp(y0 + (k >> 1), 0, g.ny - 1);
        const std::size_t i = g.index(x, y, p.z);
        const float put = static_cast<float>(w * p.amount);
        s.wet[i] = mix_moisture(s.rho[i], s.wet[i], put, p.wet);
        s.rho[i] += put;
        touched[static_cast<std::size_t>(y) * g.nx + x] = 1;
      }
    }
  }
}

}  // namespace drift::soil
