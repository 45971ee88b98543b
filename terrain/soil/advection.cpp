#include "terrain/soil/advection.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "terrain/soil/transport.h"

namespace drift::soil {

namespace {
constexpr float kFull = 1.0f - 1e-6f;  // rho + psi at which a voxel counts as full (locked)
}  // namespace

void copy_back(SoilState& s, std::size_t i) {
  s.rho[i] = s.back.rho[i];
  s.ux[i] = s.back.ux[i];
  s.uy[i] = s.back.uy[i];
  s.uz[i] = s.back.uz[i];
  s.fx[i] = s.back.fx[i];
  s.fy[i] = s.back.fy[i];
  s.fz[i] = s.back.fz[i];
  s.wet[i] = s.back.wet[i];
}

detail::Ranges advect(SoilState& s, double dt) {
  const terrain::Grid3Shape& g = s.shape;
  const float scale = static_cast<float>(dt / g.voxel_size);  // m/s -> voxels per step
  const float *ux = s.ux.data(), *uy = s.uy.data(), *uz = s.uz.data();
  const float *rho = s.rho.data(), *psi = s.psi.data();
  auto disp = [=](std::size_t i) {
    return detail::D3{std::clamp(ux[i] * scale, -1.0f, 1.0f),
                      std::clamp(uy[i] * scale, -1.0f, 1.0f),
                      std::clamp(uz[i] * scale, -1.0f, 1.0f)};
  };
  // Eq. 24: a voxel full of soil and body is locked (rho is only read here).
  auto unlocked = [=](std::size_t i) { return rho[i] + psi[i] < kFull; };
  const detail::Carried carried{
      {ux, uy, uz}, {s.fx.data(), s.fy.data(), s.fz.data()}, s.wet.data()};
  return detail::transport(
      g, s.rho.data(), detail::sender_ranges(g, s.rho.data(), unlocked, disp), unlocked, disp,
      carried, false,
      [&](std::size_t i, const detail::Gathered& r) {
        s.back.rho[i] = r.amount;
        const float inv = detail::weight_inverse(r.amount);
        s.back.ux[i] = r.u[0] * inv;
        s.back.uy[i] = r.u[1] * inv;
        s.back.uz[i] = r.u[2] * inv;
        s.back.fx[i] = r.f[0] * inv;
        s.back.fy[i] = r.f[1] * inv;
        s.back.fz[i] = r.f[2] * inv;
        s.back.wet[i] = r.amount > 0 ? std::clamp(r.m * inv, 0.0f, 1.0f) : s.wet[i];
      },
      true,
      [&](std::size_t i, float self) {  // backflow came back with zero velocity (eq. 28)
        s.ux[i] *= self;
        s.uy[i] *= self;
        s.uz[i] *= self;
      },
      [&](std::size_t i) { copy_back(s, i); });
}

namespace {

float room(const SoilState& s, std::size_t i) { return std::max(0.0f, 1.0f - s.psi[i]); }

// Calls f(c), c the index of a column's bottom voxel, for every column that
// `dirty` marks (every column when it is null); parallel over rows y.
template <class F>
void for_each_dirty_column(const terrain::Grid3Shape& g, const ColumnMask* dirty, F&& f) {
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x)
      if (!dirty || (*dirty)[static_cast<std::size_t>(y) * g.nx + x]) f(g.column(x, y));
  });
}

bool solid(const SoilState& s, std::size_t i) { return s.psi[i] >= kFull; }

// One Jacobi pass of "up one voxel", in place per column: the excess of
// voxel z is computed from the values before the pass (z is read before it is
// written, and the carry holds what z - 1 sent up). Excess under a solid
// body voxel stays where it is (bodies are solid: soil never passes through
// them, docs/soil.md, Method 4); settle_overflow sends it sideways.
void overflow_up_pass(SoilState& s, const ColumnMask* dirty) {
  const terrain::Grid3Shape& g = s.shape;
  for_each_dirty_column(g, dirty, [&](std::size_t c) {
    float carry = 0, cu[3] = {0, 0, 0}, cm = 0;
    for (int z = 0; z < g.nz; ++z) {
      const std::size_t i = c + z;
      const float r = s.rho[i];
      const bool up_open = z + 1 < g.nz && !solid(s, i + 1);
      const float ex = up_open ? std::max(0.0f, r - room(s, i)) : 0.0f;
      if (ex == 0 && carry == 0) continue;
      const float u[3] = {s.ux[i], s.uy[i], s.uz[i]};
      const float kept = r - ex, now = kept + carry;
      const float inv = detail::weight_inverse(now);
      s.ux[i] = (kept * u[0] + carry * cu[0]) * inv;
      s.uy[i] = (kept * u[1] + carry * cu[1]) * inv;
      s.uz[i] = (kept * u[2] + carry * cu[2]) * inv;
      const float m = s.wet[i];
      s.wet[i] = mix_moisture(kept, m, carry, cm);
      s.rho[i] = now;
      carry = ex;
      cm = m;
      std::copy(u, u + 3, cu);
    }
  });
}

// Weights of a heuristic over the 26 neighbours, indexed (ox+1) + 3 (oy+1) + 9 (oz+1).
std::array<float, 27> heuristic_weights(OverflowHeuristic h) {
  std::array<float, 27> w{};
  for (int oz = -1; oz <= 1; ++oz)
    for (int oy = -1; oy <= 1; ++oy)
      for (int ox = -1; ox <= 1; ++ox) {
        const int k = (ox + 1) + 3 * (oy + 1) + 9 * (oz + 1);
        if (h == OverflowHeuristic::Spread) w[k] = (ox || oy || oz) ? 1.0f : 0.0f;
        if (h == OverflowHeuristic::UpNine && oz == 1)
          w[k] = (ox ? 0.25f : 0.5f) * (oy ? 0.25f : 0.5f);
      }
  return w;
}

// One Jacobi pass of a weighted heuristic: sources spread their excess over
// their valid neighbours (normalised), every voxel gathers.
void overflow_weighted_pass(SoilState& s, const std::array<float, 27>& w) {
  const terrain::Grid3Shape& g = s.shape;
  std::vector<float>& excess = s.back.moving;
  std::vector<float>& norm = s.back.rho;  // 1 / sum of valid weights, 0 if none
  auto valid = [&](int x, int y, int z) {
    return g.contains(x, y, z) && s.psi[g.index(x, y, z)] < kFull;
  };
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x)
      for (int z = 0; z < g.nz; ++z) {
        const std::size_t i = g.index(x, y, z);
        const float ex = std::max(0.0f, s.rho[i] - room(s, i));
        float sum = 0;
        if (ex > 0)
          for (int k = 0; k < 27; ++k)
            if (w[k] > 0 && valid(x + k % 3 - 1, y + (k / 3) % 3 - 1, z + k / 9 - 1)) sum += w[k];
        excess[i] = sum > 0 ? ex : 0.0f;
        norm[i] = sum > 0 ? 1.0f / sum : 0.0f;
      }
  });
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x)
      for (int z = 0; z < g.nz; ++z) {
        const std::size_t i = g.index(x, y, z);
        float in = 0, iu[3] = {0, 0, 0}, im = 0;
        if (valid(x, y, z))
          for (int k = 0; k < 27; ++k) {
            if (w[k] <= 0) continue;
            const int sx = x - (k % 3 - 1), sy = y - ((k / 3) % 3 - 1), sz = z - (k / 9 - 1);
            if (!g.contains(sx, sy, sz)) continue;
            const std::size_t j = g.index(sx, sy, sz);
            if (excess[j] <= 0) continue;
            const float q = excess[j] * w[k] * norm[j];
            in += q;
            iu[0] += q * s.ux[j];
            iu[1] += q * s.uy[j];
            iu[2] += q * s.uz[j];
            im += q * s.wet[j];
          }
        const float kept = s.rho[i] - excess[i], now = kept + in;
        const float inv = detail::weight_inverse(now);
        s.back.ux[i] = (kept * s.ux[i] + iu[0]) * inv;
        s.back.uy[i] = (kept * s.uy[i] + iu[1]) * inv;
        s.back.uz[i] = (kept * s.uz[i] + iu[2]) * inv;
        s.back.fx[i] = now;  // the new density, until the swap below
        s.back.wet[i] = now > 1e-30f ? (kept * s.wet[i] + im) * inv : s.wet[i];
      }
  });
  s.wet.swap(s.back.wet);
  s.rho.swap(s.back.fx);
  s.ux.swap(s.back.ux);
  s.uy.swap(s.back.uy);
  s.uz.swap(s.back.uz);
}

}  // namespace

void resolve_overflow(SoilState& s, OverflowHeuristic h, int passes, const ColumnMask* dirty) {
  for (int p = 0; p < passes; ++p) {
    if (h == OverflowHeuristic::Up)
      overflow_up_pass(s, dirty);
    else
      overflow_weighted_pass(s, heuristic_weights(h));
  }
}

namespace {

// Sends `carry` of voxel i's excess to the nearest room: a breadth-first
// walk from it through open voxels, face neighbours in a fixed order (up
// first, then x, y; down only if `down`), filling the room it meets; returns
// what found none. Nearest rather than straight up: the excess of a pile
// pressed by a body grows the pile where its surface is nearest (a heap ahead
// of a blade, windrows beside it) instead of a wall of soil climbing the
// body's face to its top, from where it spilled into the blade's path.
// Without downward steps it never passes under a body's cutting edge into
// the room behind it.
float route_excess(SoilState& s, std::size_t i, float carry, bool down) {
  const float m = s.wet[i];  // the excess keeps the moisture of the soil it left
  const terrain::Grid3Shape& g = s.shape;
  constexpr int kOff[6][3] = {{0, 0, 1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, -1}};
  constexpr std::size_t kMaxVisits = 1 << 16;
  std::vector<std::size_t>& queue = s.back.walk;
  std::vector<std::uint8_t>& seen = s.back.visited;
  queue.assign(1, i);
  seen[i] = 1;
  for (std::size_t head = 0; head < queue.size() && carry > 0; ++head) {
    const std::size_t v = queue[head];
    const int z = static_cast<int>(v % g.nz), xy = static_cast<int>(v / g.nz);
    const int x = xy % g.nx, y = xy / g.nx;
    for (int k = 0; k < (down ? 6 : 5) && carry > 0; ++k) {
      const int* o = kOff[k];
      if (!g.contains(x + o[0], y + o[1], z + o[2])) continue;
      const std::size_t n = g.index(x + o[0], y + o[1], z + o[2]);
      if (solid(s, n) || seen[n] || queue.size() >= kMaxVisits) continue;
      seen[n] = 1;
      queue.push_back(n);
      const float take = std::min(carry, std::max(0.0f, room(s, n) - s.rho[n]));
      if (take > 0) s.wet[n] = mix_moisture(s.rho[n], s.wet[n], take, m);
      s.rho[n] += take;
      carry -= take;
    }
  }
  for (std::size_t v : queue) seen[v] = 0;
  return carry;
}

// Settles voxel i: its excess over its room goes to the nearest room,
// upwards and sideways first, then also downwards; what finds none stays.
void settle_voxel(SoilState& s, std::size_t i) {
  float carry = s.rho[i] - room(s, i);
  if (carry <= 0) return;
  s.rho[i] -= carry;
  carry = route_excess(s, i, carry, false);
  if (carry > 0) carry = route_excess(s, i, carry, true);
  s.rho[i] += carry;
}

// Soil inside a solid body voxel (a body moved onto it faster than the
// deformation pushed it out) goes to the nearest open voxel of its column,
// the body's nearer face (upwards on a tie), never through to the far side.
// Returns false if the column has no open voxel at all.
bool expel_from_body(SoilState& s, std::size_t c, int nz) {
  bool placed = true;
  for (int z = 0; z < nz; ++z) {
    if (!solid(s, c + z) || s.rho[c + z] <= 0) continue;
    int up = z + 1, down = z - 1;
    while (up < nz && solid(s, c + up)) ++up;
    while (down >= 0 && solid(s, c + down)) --down;
    const bool has_up = up < nz, has_down = down >= 0;
    if (!has_up && !has_down) {
      placed = false;
      continue;
    }
    const int to = !has_down || (has_up && up - z <= z - down) ? up : down;
    s.wet[c + to] = mix_moisture(s.rho[c + to], s.wet[c + to], s.rho[c + z], s.wet[c + z]);
    s.rho[c + to] += s.rho[c + z];
    s.rho[c + z] = 0;
  }
  return placed;
}

}  // namespace

void settle_overflow(SoilState& s, const ColumnMask* dirty) {
  const terrain::Grid3Shape& g = s.shape;
  std::vector<std::uint8_t> over(g.columns(), 0);  // columns with excess somewhere
  for_each_dirty_column(g, dirty, [&](std::size_t c) {
    expel_from_body(s, c, g.nz);
    for (int z = 0; z < g.nz && !over[c / g.nz]; ++z)
      over[c / g.nz] = s.rho[c + z] > room(s, c + z);
  });
  // Sequential, in column order and upwards (the walks write other columns):
  // the same bits on any thread count. Only overflowed voxels walk.
  for (std::size_t col = 0; col < over.size(); ++col) {
    if (!over[col]) continue;
    for (int z = 0; z < g.nz; ++z) settle_voxel(s, col * g.nz + z);
  }
}

void apply_gravity(SoilState& s, double gravity, double dt) {
  const float dv = static_cast<float>(-gravity * dt);
  const std::size_t n = s.size();
  tbb::parallel_for(std::size_t{0}, n, std::size_t{1} << 16, [&](std::size_t begin) {
    const std::size_t end = std::min(n, begin + (std::size_t{1} << 16));
    for (std::size_t i = begin; i < end; ++i) {
      if (s.rho[i] > 0) {
        s.uz[i] += dv;
      } else if (s.ux[i] != 0 || s.uy[i] != 0 || s.uz[i] != 0 || s.fx[i] != 0 || s.fy[i] != 0 ||
                 s.fz[i] != 0) {
        // Stored only where something is set: the air is most of the grid,
        // and rewriting its zeros every step dirtied 6 MB at 64^3.
        s.ux[i] = s.uy[i] = s.uz[i] = 0;
        s.fx[i] = s.fy[i] = s.fz[i] = 0;
      }
    }
  });
}

}  // namespace drift::soil
