#include "snow/snow_cover.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "terrain/derivatives.h"
#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/parameter.h"

namespace drift::snow {

using Eigen::Vector3f;
using terrain::HeightField;

namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

// Rows in fixed blocks: the partition is the same for any thread count.
template <class Fn>
void for_rows(int rows, Fn fn) {
  tbb::parallel_for(
      tbb::blocked_range<int>(0, rows, 8),
      [&](const tbb::blocked_range<int>& r) {
        for (int row = r.begin(); row < r.end(); ++row) fn(row);
      },
      tbb::simple_partitioner());
}

// The 12 triangles around a grid point, both diagonal splits (paper fig. 9),
// as the (dx, drow) offsets of their two other vertices, counter-clockwise
// seen from above (x east, rows south).
constexpr std::array<std::array<int, 4>, 12> kTriangles = {{
    // split "\": NW-SE diagonals
    {-1, -1, 0, -1},
    {-1, 0, -1, -1},
    {0, -1, 1, 0},
    {-1, 0, 0, 1},
    {1, 0, 1, 1},
    {0, 1, 1, 1},
    // split "/": NE-SW diagonals
    {0, -1, 1, -1},
    {1, -1, 1, 0},
    {-1, 0, 0, -1},
    {1, 0, 0, 1},
    {-1, 1, -1, 0},
    {0, 1, -1, 1},
}};

// Position of cell (x, row) in a local metric frame (x east, y north, z up),
// the border clamped.
Vector3f position(const HeightField& dem, int x, int row, float dx, float dy) {
  const int cx = std::clamp(x, 0, dem.width() - 1), cr = std::clamp(row, 0, dem.height() - 1);
  return {cx * dx, -cr * dy, dem(cx, cr)};
}

float smoothstep(float e0, float e1, float v) {
  const float t = std::clamp((v - e0) / std::max(e1 - e0, 1e-6f), 0.0f, 1.0f);
  return t * t * (3 - 2 * t);
}

void require(bool ok, const std::string& message) {
  if (!ok) throw Error(message);
}

}  // namespace

int smoothing_neighbour_count(int region) { return 4 * region + 2 * region * (region - 1); }

HeightField smooth(const HeightField& dem, int region) {
  const int w = dem.width(), h = dem.height(), n = region;
  // Padded copy (edge cells repeated) so that the diamond's rows are plain
  // shifted spans and the inner loop vectorises.
  const int pw = w + 2 * n;
  std::vector<float> padded(static_cast<std::size_t>(pw) * (h + 2 * n));
  for_rows(h + 2 * n, [&](int pr) {
    const int row = std::clamp(pr - n, 0, h - 1);
    for (int px = 0; px < pw; ++px)
      padded[static_cast<std::size_t>(pr) * pw + px] = dem(std::clamp(px - n, 0, w - 1), row);
  });
  HeightField out(w, h, 0.0f, dem.geo());
  const float inv_count = 1.0f / static_cast<float>(smoothing_neighbour_count(n));
  for_rows(h, [&](int row) {
    thread_local std::vector<float> sum;
    sum.assign(w, 0.0f);
    for (int dr = -n; dr <= n; ++dr) {
      const int reach = n - std::abs(dr);
      const float* line = &padded[static_cast<std::size_t>(row + n + dr) * pw + n];
      for (int dx = -reach; dx <= reach; ++dx) {
        if (dr == 0 && dx == 0) continue;
        const float* src = line + dx;
        for (int x = 0; x < w; ++x) sum[x] += src[x];
      }
    }
    for (int x = 0; x < w; ++x) out(x, row) = 0.5f * (dem(x, row) + sum[x] * inv_count);
  });
  return out;
}

float tsa_at(const HeightField& dem, const terrain::Grid<Vector3f>& normals, int x, int row) {
  const float dx = static_cast<float>(dem.geo().cell_size_x());
  const float dy = static_cast<float>(dem.geo().cell_size_y());
  const Vector3f X = position(dem, x, row, dx, dy);
  const Vector3f& N = normals(x, row);
  float best = kInfinity;
  // The far vertices of the 12 triangles are the 8 neighbours.
  for (int dr = -1; dr <= 1; ++dr) {
    for (int dc = -1; dc <= 1; ++dc) {
      if (dr == 0 && dc == 0) continue;
      const int vx = x + dc, vr = row + dr;
      if (vx < 0 || vr < 0 || vx >= dem.width() || vr >= dem.height()) continue;
      const Vector3f P = position(dem, vx, vr, dx, dy);
      const Vector3f& M = normals(vx, vr);
      // Paper eq. (3): the sphere tangent at X (centre X + tN) that touches
      // the tangent plane (P, M) has t = ((X - P) . M) / (1 - N . M).
      const float denominator = 1.0f - N.dot(M);
      const float numerator = (X - P).dot(M);
      if (denominator <= 1e-7f || numerator <= 0.0f) continue;  // no bound from this plane
      best = std::min(best, numerator / denominator);
    }
  }
  return best;
}

HeightField tangent_sphere_accessibility(const HeightField& dem) {
  const terrain::Grid<Vector3f> normals = terrain::normals(dem);
  HeightField out(dem.width(), dem.height(), 0.0f, dem.geo());
  out.geo().nodata = std::nullopt;
  for_rows(dem.height(), [&](int row) {
    for (int x = 0; x < dem.width(); ++x) out(x, row) = tsa_at(dem, normals, x, row);
  });
  return out;
}

namespace {

void check_cover_input(const HeightField& dem, const CoverOptions& o) {
  o.validate();
  require(dem.width() >= 3 && dem.height() >= 3, "the DEM must be at least 3 x 3 cells");
  require(dem.geo().north_up() && dem.geo().cell_size_x() > 0 && dem.geo().cell_size_y() > 0,
          "the DEM must be north-up with positive cell sizes; warp it with drift import");
  require(!terrain::is_geographic(dem.geo().crs_wkt),
          "the DEM is in degrees; the descriptor needs metres: run drift import first");
  std::size_t nodata = 0;
  for (float v : dem.values()) nodata += std::isnan(v) ? 1 : 0;
  require(nodata == 0, "the DEM has " + std::to_string(nodata) +
                           " nodata cells; drift import fills them (run it first)");
}

bool southern_hemisphere(const HeightField& dem, Hemisphere hemisphere) {
  if (hemisphere == Hemisphere::South) return true;
  if (hemisphere == Hemisphere::Auto && !dem.geo().crs_wkt.empty())
    return terrain::centre_lonlat(dem.geo(), dem.width(), dem.height())[1] < 0.0;
  return false;
}

// Steps 3-4: the transfer g (paper eq. 4) of the accessibility and the
// altitude factor (SPEC 3b.4: on the snow amount); t = 1 - snow.
HeightField transfer(const HeightField& dem, const HeightField& accessibility,
                     const CoverOptions& o) {
  const double cell = dem.geo().cell_size_x();
  const float r = static_cast<float>(o.radius_m > 0.0 ? o.radius_m : o.radius_cells * cell);
  const float b = static_cast<float>(o.floor);
  float z_max = -kInfinity;
  for (float v : dem.values()) z_max = std::max(z_max, v);
  auto altitude_factor = [&](float z) {
    if (o.snow_line_m) {
      const float line = static_cast<float>(*o.snow_line_m),
                  half = 0.5f * static_cast<float>(o.band_m);
      return smoothstep(line - half, line + half, z);
    }
    const float a = z_max > 0.0f ? std::clamp(z / z_max, 0.0f, 1.0f) : 0.0f;
    return a * a;
  };
  HeightField t(dem.width(), dem.height(), 0.0f, dem.geo());
  t.geo().nodata = std::nullopt;
  for_rows(dem.height(), [&](int row) {
    for (int x = 0; x < dem.width(); ++x) {
      const float tsa = accessibility(x, row);
      const float g = tsa >= r ? 1.0f : (1.0f - b) * tsa / r + b;
      const float snow = (1.0f - g) * altitude_factor(dem(x, row));
      t(x, row) = 1.0f - snow;
    }
  });
  return t;
}

// phi of one cell (paper lines 10-15): triangles facing within theta1 of the
// sun's side (sun_y: +1 north, -1 south) count by their angle from it,
// averaged over the 12 triangles; 1 is no effect.
float sun_phi(const HeightField& smoothed, int x, int row, float dx, float dy, float sun_y,
              float theta1) {
  const float cos_theta1 = std::cos(theta1);
  const Vector3f X = position(smoothed, x, row, dx, dy);
  float phi_sum = 0.0f;
  for (const auto& tri : kTriangles) {
    const Vector3f a = position(smoothed, x + tri[0], row + tri[1], dx, dy) - X;
    const Vector3f c = position(smoothed, x + tri[2], row + tri[3], dx, dy) - X;
    const Vector3f m = a.cross(c);  // the face normal, up or down (sign below)
    const float h2 = m.x() * m.x() + m.y() * m.y();
    float phi = 1.0f;  // 1: no effect (outside the range, or flat)
    if (h2 > 1e-12f * m.squaredNorm()) {
      // Cosine of the angle between the face's aspect and the sun's side.
      const float sign = m.z() < 0.0f ? -1.0f : 1.0f;
      const float cos_off = sign * m.y() * sun_y / std::sqrt(h2);
      if (cos_off >= cos_theta1) phi = std::acos(std::min(cos_off, 1.0f)) / theta1;
    }
    phi_sum += phi;
  }
  return phi_sum / static_cast<float>(kTriangles.size());
}

// Step 6: triangles facing the sun's side lose snow, the more the closer to it.
HeightField sun_correction(const HeightField& smoothed, const HeightField& t, double range_deg,
                           bool southern) {
  const float dx = static_cast<float>(smoothed.geo().cell_size_x());
  const float dy = static_cast<float>(smoothed.geo().cell_size_y());
  // Horizontal unit vector towards the sun's side: south (0, -1) in the
  // northern hemisphere, north (0, 1) in the southern.
  const float sun_y = southern ? 1.0f : -1.0f;
  const float theta1 = static_cast<float>(range_deg * std::numbers::pi / 180.0);
  HeightField corrected = t;
  for_rows(t.height(), [&](int row) {
    for (int x = 0; x < t.width(); ++x) {
      const float phi = sun_phi(smoothed, x, row, dx, dy, sun_y, theta1);
      corrected(x, row) = t(x, row) * phi + (1.0f - phi);
    }
  });
  return corrected;
}

}  // namespace

void CoverOptions::validate() const {
  terrain::require_in("region", region, 1, 32, "cells");
  terrain::require_in("iterations", iterations, 0, 100);
  terrain::require_in("floor", floor, 0.0, 1.0);
  terrain::require_in("sun_range_deg", sun_range_deg, 0.0, 90.0, "degrees");
  terrain::require_field(radius_m >= 0.0 && std::isfinite(radius_m), "radius_m", radius_m,
                         "[0, inf) m (0: radius_cells)");
  terrain::require_field(radius_cells > 0.0 && std::isfinite(radius_cells), "radius_cells",
                         radius_cells, "(0, inf)");
  terrain::require_field(band_m > 0.0 && std::isfinite(band_m), "band_m", band_m, "(0, inf) m");
}

CoverResult snow_cover(const HeightField& dem, const CoverOptions& o, const ProgressFn& progress) {
  check_cover_input(dem, o);
  CoverResult result;
  result.southern = southern_hemisphere(dem, o.hemisphere);

  // 1. Smoothing (paper sec. 4.1 lines 1-3), k times.
  progress(0.0, "smoothing");
  HeightField smoothed = dem;
  for (int i = 0; i < o.iterations; ++i) {
    smoothed = smooth(smoothed, o.region);
    if (!progress(0.4 * (i + 1) / std::max(o.iterations, 1), "")) throw Cancelled();
  }
  // 2. TSA of the smoothed surface (lines 4-5).
  result.accessibility = tangent_sphere_accessibility(smoothed);
  if (!progress(0.7, "accessibility")) throw Cancelled();
  // 3-4. Transfer and altitude.
  HeightField t = transfer(dem, result.accessibility, o);
  // 5. Smooth t once (its locality makes colours blotchy otherwise).
  t = smooth(t, 1);
  // 6. Sun (lines 10-15).
  if (o.sun_range_deg > 0.0) t = sun_correction(smoothed, t, o.sun_range_deg, result.southern);
  progress(1.0, "");
  result.descriptor = std::move(t);
  return result;
}

}  // namespace drift::snow
