#include "snow/snow_cover.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "snow/cover_parameters.h"
#include "terrain/angles.h"
#include "terrain/derivatives.h"
#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/memory.h"
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

int region_in_cells(const CoverOptions& o, double cell_m) {
  if (o.region_cells > 0) return o.region_cells;
  return std::max(1, static_cast<int>(std::lround(o.region * kPaperCellM / cell_m)));
}

double radius_in_metres(const CoverOptions& o, double cell_m) {
  return o.radius_cells > 0.0 ? o.radius_cells * cell_m : o.radius_m;
}

namespace {

// Row prefix sums (double) of the DEM padded by n cells on every side (edge
// cells repeated): row pr holds sum[px] = the first px padded heights.
std::vector<double> padded_row_sums(const HeightField& dem, int n) {
  const int w = dem.width(), h = dem.height(), pw = w + 2 * n + 1;
  std::vector<double> sums(static_cast<std::size_t>(pw) * (h + 2 * n));
  for_rows(h + 2 * n, [&](int pr) {
    const int row = std::clamp(pr - n, 0, h - 1);
    double* line = &sums[static_cast<std::size_t>(pr) * pw];
    line[0] = 0.0;
    for (int px = 0; px + 1 < pw; ++px)
      line[px + 1] = line[px] + dem(std::clamp(px - n, 0, w - 1), row);
  });
  return sums;
}

}  // namespace

HeightField smooth(const HeightField& dem, int region) {
  const int w = dem.width(), h = dem.height(), n = region, pw = w + 2 * n + 1;
  const std::vector<double> sums = padded_row_sums(dem, n);
  HeightField out(w, h, 0.0f, dem.geo());
  const double inv_count = 1.0 / smoothing_neighbour_count(n);
  for_rows(h, [&](int row) {
    for (int x = 0; x < w; ++x) {
      double sum = -static_cast<double>(dem(x, row));  // the diamond without its centre
      for (int dr = -n; dr <= n; ++dr) {
        const int reach = n - std::abs(dr);
        const double* line = &sums[static_cast<std::size_t>(row + n + dr) * pw];
        sum += line[x + n + reach + 1] - line[x + n - reach];
      }
      out(x, row) = static_cast<float>(0.5 * (dem(x, row) + sum * inv_count));
    }
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

void validate(const HeightField& dem, const CoverOptions& o) {
  o.validate();
  require(dem.width() >= 3 && dem.height() >= 3, "the DEM must be at least 3 x 3 cells");
  require(dem.geo().north_up() && dem.geo().cell_size_x() > 0 && dem.geo().cell_size_y() > 0,
          "the DEM must be north-up with positive cell sizes; warp it with drift import");
  require(!terrain::is_geographic(dem.geo().crs_wkt),
          "the DEM is in degrees; the descriptor needs metres: run drift import first");
  const int n = region_in_cells(o, dem.geo().cell_size_x());
  require(n <= 256, "the smoothing region is " + std::to_string(n) +
                        " cells on this DEM (over 256): lower --region or resample the DEM");
  std::size_t nodata = 0;
  for (float v : dem.values()) nodata += std::isnan(v) ? 1 : 0;
  require(nodata == 0, "the DEM has " + std::to_string(nodata) +
                           " nodata cells; drift import fills them (run it first)");
  // The smoothed field, the TSA, the descriptor and two working grids.
  require_memory(dem.size() * sizeof(float) * 6,
                 "the snow cover of a " + std::to_string(dem.width()) + " x " +
                     std::to_string(dem.height()) + " DEM",
                 "crop or resample the DEM first (drift import --crop, --resample)");
}

bool in_southern_hemisphere(const HeightField& dem, Hemisphere hemisphere) {
  if (hemisphere != Hemisphere::Auto) return hemisphere == Hemisphere::South;
  if (dem.geo().crs_wkt.empty()) return false;
  return terrain::centre_lonlat(dem.geo(), dem.width(), dem.height())[1] < 0.0;
}

// Altitude factor a(z) (docs/snow.md, Steps, 4): (z / z_max)^2, or a smooth step
// across a snow line.
struct Altitude {
  float z_max;
  const CoverOptions& o;
  float operator()(float z) const {
    if (o.snow_line_m) {
      const float line = static_cast<float>(*o.snow_line_m),
                  half = 0.5f * static_cast<float>(o.band_m);
      return smoothstep(line - half, line + half, z);
    }
    const float a = z_max > 0.0f ? std::clamp(z / z_max, 0.0f, 1.0f) : 0.0f;
    return a * a;
  }
};

// Steps 3-4: transfer g (eq. 4) and altitude on the snow amount; t = 1 - snow.
HeightField descriptor_from_accessibility(const HeightField& dem, const HeightField& tsa,
                                          const CoverOptions& o) {
  const float r = static_cast<float>(radius_in_metres(o, dem.geo().cell_size_x()));
  const float b = static_cast<float>(o.floor);
  float z_max = -kInfinity;
  for (float v : dem.values()) z_max = std::max(z_max, v);
  const Altitude altitude{z_max, o};
  HeightField t(dem.width(), dem.height(), 0.0f, dem.geo());
  t.geo().nodata = std::nullopt;
  for_rows(dem.height(), [&](int row) {
    for (int x = 0; x < dem.width(); ++x) {
      const float a = tsa(x, row);
      const float g = a >= r ? 1.0f : (1.0f - b) * a / r + b;
      t(x, row) = 1.0f - (1.0f - g) * altitude(dem(x, row));
    }
  });
  return t;
}

// phi of one triangle (offsets of its two other vertices) around X for the sun
// step: its aspect's angle from the sun's side over theta1, or 1 (no effect)
// when it faces farther away than theta1 or is flat.
float triangle_phi(const HeightField& smoothed, int x, int row, const std::array<int, 4>& tri,
                   float sun_y, float theta1) {
  const float dx = static_cast<float>(smoothed.geo().cell_size_x());
  const float dy = static_cast<float>(smoothed.geo().cell_size_y());
  const Vector3f X = position(smoothed, x, row, dx, dy);
  const Vector3f a = position(smoothed, x + tri[0], row + tri[1], dx, dy) - X;
  const Vector3f c = position(smoothed, x + tri[2], row + tri[3], dx, dy) - X;
  const Vector3f m = a.cross(c);  // the face normal, up or down (sign below)
  const float h2 = m.x() * m.x() + m.y() * m.y();
  if (h2 <= 1e-12f * m.squaredNorm()) return 1.0f;
  // Cosine of the angle between the face's aspect and the sun's side.
  const float sign = m.z() < 0.0f ? -1.0f : 1.0f;
  const float cos_off = sign * m.y() * sun_y / std::sqrt(h2);
  if (cos_off < std::cos(theta1)) return 1.0f;
  return std::acos(std::min(cos_off, 1.0f)) / theta1;
}

// Step 6 at one point. The paper (lines 10-15) updates t = t phi + (1 - phi)
// once per facing triangle: the snow 1 - t is multiplied by each triangle's
// phi. The mean variant applies the average phi of the 12 once.
float sun_corrected(float t, const HeightField& smoothed, int x, int row, float sun_y, float theta1,
                    SunStep step) {
  float product = 1.0f, sum = 0.0f;
  for (const auto& tri : kTriangles) {
    const float phi = triangle_phi(smoothed, x, row, tri, sun_y, theta1);
    product *= phi;
    sum += phi;
  }
  const float phi = step == SunStep::PerTriangle ? product : sum / kTriangles.size();
  return t * phi + (1.0f - phi);
}

// Step 6 over the grid: sun_y is +1 (north) in the southern hemisphere, -1 (south) otherwise.
HeightField apply_sun(const HeightField& t, const HeightField& smoothed, const CoverOptions& o,
                      bool southern) {
  const float sun_y = southern ? 1.0f : -1.0f;
  const float theta1 = static_cast<float>(terrain::radians(o.sun_range_deg));
  HeightField corrected = t;
  for_rows(t.height(), [&](int row) {
    for (int x = 0; x < t.width(); ++x)
      corrected(x, row) = sun_corrected(t(x, row), smoothed, x, row, sun_y, theta1, o.sun_step);
  });
  return corrected;
}

}  // namespace

void CoverOptions::validate() const {
  for (const CoverParameter& p : cover_parameters()) p.require(*this);
  if (snow_line_m)
    terrain::require_field(std::isfinite(*snow_line_m), "snow_line_m", *snow_line_m,
                           "(-inf, inf) m");
}

CoverResult snow_cover(const HeightField& dem, const CoverOptions& o, const ProgressFn& progress) {
  validate(dem, o);
  CoverResult result;
  result.southern = in_southern_hemisphere(dem, o.hemisphere);
  // 1. Smoothing (paper sec. 4.1 lines 1-3), k times over the region in cells.
  progress(0.0, "smoothing");
  const int n = region_in_cells(o, dem.geo().cell_size_x());
  HeightField smoothed = dem;
  for (int i = 0; i < o.iterations; ++i) {
    smoothed = smooth(smoothed, n);
    if (!progress(0.4 * (i + 1) / std::max(o.iterations, 1), "")) throw Cancelled();
  }
  // 2. TSA of the smoothed surface (lines 4-5).
  result.accessibility = tangent_sphere_accessibility(smoothed);
  if (!progress(0.7, "accessibility")) throw Cancelled();
  // 3-4. Transfer and altitude (lines 6-7; docs/snow.md, Steps, 4); 5. smooth t
  // once (line 9).
  HeightField t = smooth(descriptor_from_accessibility(dem, result.accessibility, o), 1);
  // 6. Sun (lines 10-15).
  if (o.sun_range_deg > 0.0) t = apply_sun(t, smoothed, o, result.southern);
  progress(1.0, "");
  result.descriptor = std::move(t);
  return result;
}

}  // namespace drift::snow
