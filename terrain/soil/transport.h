// The 27-neighbour transport shared by advection and force propagation
// (paper 004, sec. 3.2.1 eqs. 22-28 and sec. 3.2.4 eqs. 34-35): every voxel's
// moving amount is displaced by at most one voxel per axis, its unit cube
// spread trilinearly over the (up to) eight voxels it overlaps (lambda). A
// voxel that does not accept inflow (locked, rigid or outside the grid) sends
// what would enter it back to the source as backflow. Each voxel gathers its
// own result from its 27 neighbours (it writes only itself), so the passes run
// in parallel and give the same bits on any number of threads.
//
// Only columns near moving soil do the full gather: per column the z-range of
// voxels that send anything to another voxel is found first, and a voxel no
// sender can reach keeps its amount (its own backflow) without a gather.
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "terrain/grid3.h"

namespace drift::soil::detail {

struct D3 {
  float x = 0, y = 0, z = 0;
};

// lambda along one axis: share of a cube displaced by d (|d| <= 1) that lands
// at offset o in {-1, 0, 1}.
inline float axis_share(int o, float d) {
  if (o == 0) return 1.0f - std::abs(d);
  return ((o > 0 && d > 0) || (o < 0 && d < 0)) ? std::abs(d) : 0.0f;
}

inline int sign_of(float d) { return d > 0 ? 1 : (d < 0 ? -1 : 0); }

// 1 / w for dividing a w-weighted sum back into a mean; 0 for w so small that
// 1 / w would overflow a float (a denormal trace of soil: 0 * inf is NaN).
inline float weight_inverse(float w) { return w > 1e-30f ? 1.0f / w : 0.0f; }

// What one voxel gathered: the amount (stay + backflow + inflows) and the
// amount-weighted sums of the carried vectors and of the moisture (which
// goes with the soil: the same products a * lambda, so water is conserved as
// mass is).
struct Gathered {
  float amount = 0;
  float u[3] = {0, 0, 0};
  float f[3] = {0, 0, 0};
  float m = 0;
};

struct Carried {
  const float* u[3];
  const float* f[3];
  const float* m;
};

// What voxel (x, y, z) holding `a` sends to other voxels that accept it:
// the sum of the very products a * lambda its targets gather, so that what it
// keeps, a - sent, makes the step conserve mass to rounding (keeping
// a * lambda_self + backflow instead rounds the same way in every resting
// voxel and drifts).
template <class Accept>
float sent_amount(const terrain::Grid3Shape& s, const Accept& accept, int x, int y, int z,
                  const D3& d, float a) {
  const int sx = sign_of(d.x), sy = sign_of(d.y), sz = sign_of(d.z);
  if (!sx && !sy) {  // straight up or down: the one target (most soil at rest)
    const int tz = z + sz;
    return sz && tz >= 0 && tz < s.nz && accept(s.index(x, y, tz)) ? a * axis_share(sz, d.z) : 0.0f;
  }
  float sent = 0;
  for (int c = 1; c < 8; ++c) {
    if ((c & 1 && !sx) || (c & 2 && !sy) || (c & 4 && !sz)) continue;
    const int ox = (c & 1) ? sx : 0, oy = (c & 2) ? sy : 0, oz = (c & 4) ? sz : 0;
    const float l = axis_share(ox, d.x) * axis_share(oy, d.y) * axis_share(oz, d.z);
    if (l <= 0) continue;
    const int tx = x + ox, ty = y + oy, tz = z + oz;
    if (s.contains(tx, ty, tz) && accept(s.index(tx, ty, tz))) sent += a * l;
  }
  return sent;
}

// True if voxel (x, y, z) sends any of its amount to another voxel.
template <class Disp, class Accept>
bool sends(const terrain::Grid3Shape& s, const float* amount, const Accept& accept, Disp& disp,
           int x, int y, int z) {
  const std::size_t i = s.index(x, y, z);
  if (amount[i] <= 0) return false;
  const D3 d = disp(i);
  if (d.x == 0 && d.y == 0 && d.z == 0) return false;
  return sent_amount(s, accept, x, y, z, d, amount[i]) > 0;
}

// Per column a z-range [first, last] (first > last: empty).
using Ranges = std::vector<std::pair<int, int>>;

// Per column, the z-range of the voxels that send something.
template <class Disp, class Accept>
Ranges sender_ranges(const terrain::Grid3Shape& s, const float* amount, const Accept& accept,
                     Disp disp) {
  Ranges ranges(s.columns(), {s.nz, -1});
  tbb::parallel_for(0, s.ny, [&](int y) {
    for (int x = 0; x < s.nx; ++x) {
      auto& r = ranges[static_cast<std::size_t>(y) * s.nx + x];
      for (int z = 0; z < s.nz; ++z)
        if (sends(s, amount, accept, disp, x, y, z)) {
          r.first = std::min(r.first, z);
          r.second = z;
        }
    }
  });
  return ranges;
}

// Full gather at one voxel.
template <class Disp, class Accept>
Gathered gather(const terrain::Grid3Shape& s, const float* amount, const Accept& accept, Disp& disp,
                const Carried& c, bool backflow_keeps_u, int x, int y, int z) {
  Gathered g;
  const std::size_t i = s.index(x, y, z);
  const float a = amount[i];
  if (a > 0) {
    const D3 d = disp(i);
    const float kept = a - sent_amount(s, accept, x, y, z, d, a);  // stays + backflow
    const float stay = a * axis_share(0, d.x) * axis_share(0, d.y) * axis_share(0, d.z);
    g.amount = kept;
    const float wu = backflow_keeps_u ? kept : std::min(stay, kept);
    for (int k = 0; k < 3; ++k) {
      g.u[k] = wu * c.u[k][i];
      g.f[k] = kept * c.f[k][i];
    }
    g.m = kept * c.m[i];
  }
  if (!accept(i)) return g;
  for (int oy = -1; oy <= 1; ++oy)
    for (int ox = -1; ox <= 1; ++ox)
      for (int oz = -1; oz <= 1; ++oz) {
        if (!ox && !oy && !oz) continue;
        const int nx = x - ox, ny = y - oy, nz = z - oz;  // the sender, offset o behind us
        if (!s.contains(nx, ny, nz)) continue;
        const std::size_t n = s.index(nx, ny, nz);
        const float an = amount[n];
        if (an <= 0) continue;
        const D3 d = disp(n);
        const float l = axis_share(ox, d.x) * axis_share(oy, d.y) * axis_share(oz, d.z);
        if (l <= 0) continue;
        const float in = an * l;
        g.amount += in;
        for (int k = 0; k < 3; ++k) {
          g.u[k] += in * c.u[k][n];
          g.f[k] += in * c.f[k][n];
        }
        g.m += in * c.m[n];
      }
  return g;
}

// Runs the transport from the voxels in `senders` (every voxel that sends
// anything must lie in its column's range; more is harmless). Voxels some
// sender can reach gather their result and `finish(i, gathered)` stores it in
// a back buffer; once every gather is done `commit(i)` copies it to the
// front. If `with_idle`, a voxel out of every sender's reach holding soil gets
// `idle(i, self_share)` instead, in place: it keeps its amount (what would
// have left it came back) and only its own share `self_share` stayed in
// motion. Nobody reads an idle voxel's carried values (only senders' and the
// gathering voxel's own are read), so the in-place update is safe, and the
// passes cost what the moving soil covers. Returns the reach per column.
template <class Disp, class Accept, class Finish, class Idle, class Commit>
Ranges transport(const terrain::Grid3Shape& s, const float* amount, const Ranges& senders,
                 const Accept& accept, Disp disp, const Carried& c, bool backflow_keeps_u,
                 Finish finish, bool with_idle, Idle idle, Commit commit) {
  Ranges reach(s.columns(), {s.nz, -1});
  tbb::parallel_for(0, s.ny, [&](int y) {
    Disp local = disp;
    for (int x = 0; x < s.nx; ++x) {
      int lo = s.nz, hi = -1;
      for (int cy = std::max(0, y - 1); cy <= std::min(s.ny - 1, y + 1); ++cy)
        for (int cx = std::max(0, x - 1); cx <= std::min(s.nx - 1, x + 1); ++cx) {
          const auto& r = senders[static_cast<std::size_t>(cy) * s.nx + cx];
          if (r.first > r.second) continue;
          lo = std::min(lo, std::max(0, r.first - 1));
          hi = std::max(hi, std::min(s.nz - 1, r.second + 1));
        }
      reach[static_cast<std::size_t>(y) * s.nx + x] = {lo, hi};
      for (int z = lo; z <= hi; ++z)
        finish(s.index(x, y, z), gather(s, amount, accept, local, c, backflow_keeps_u, x, y, z));
      if (!with_idle) continue;
      for (int z = 0; z < s.nz; ++z) {
        if (z == lo) z = hi + 1;
        if (z >= s.nz) break;
        const std::size_t i = s.index(x, y, z);
        if (amount[i] <= 0) continue;
        const D3 d = local(i);
        idle(i, axis_share(0, d.x) * axis_share(0, d.y) * axis_share(0, d.z));
      }
    }
  });
  tbb::parallel_for(0, s.ny, [&](int y) {
    for (int x = 0; x < s.nx; ++x) {
      const auto [lo, hi] = reach[static_cast<std::size_t>(y) * s.nx + x];
      for (int z = lo; z <= hi; ++z) commit(s.index(x, y, z));
    }
  });
  return reach;
}

}  // namespace drift::soil::detail
