#include "snow/snow_cover.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "snow/cover_parameters.h"
#include "terrain/angles.h"
#include "terrain/derivatives.h"
#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/memory.h"
#include "terrain/parameter.h"
#include "terrain/raster_blocks.h"
#include "terrain/raster_io.h"

namespace drift::snow {

using Eigen::Vector3f;
using terrain::HeightField;

namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// GDAL's block cache, as the block reader and writer hold it (terrain/raster_blocks.h).
constexpr std::uint64_t kGdalCacheBytes = std::uint64_t{64} << 20;

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

// Cell (x + dc, row + dr), the border clamped, from cell (x, row) in a local
// metric frame (x east, y north, z up). Differences of whole cells, not of two
// positions from the grid's corner: the same bits wherever the pair lies in the
// grid, so in a window of it too (the tiled descriptor).
Vector3f offset(const HeightField& dem, int x, int row, int dc, int dr, float dx, float dy) {
  const int cx = std::clamp(x + dc, 0, dem.width() - 1);
  const int cr = std::clamp(row + dr, 0, dem.height() - 1);
  return {static_cast<float>(cx - x) * dx, -static_cast<float>(cr - row) * dy,
          dem(cx, cr) - dem(x, row)};
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

// Heights as fixed-point integers of 2^-32 m: exact for every float height of
// at least 2^-9 m in magnitude (finer bits of smaller ones are cut, the same
// way wherever the cell lies); |z| <= 1e7 m (terrain/raster_io.h) is < 2^56.
using Fixed = std::int64_t;
__extension__ typedef __int128 FixedSum;      // a row's sum: 2^56 a cell, room for 2^70 cells
constexpr double kFixedScale = 4294967296.0;  // 2^32: exact in double
inline Fixed to_fixed(float v) { return static_cast<Fixed>(static_cast<double>(v) * kFixedScale); }

// Rows of the output smoothed together (at least 4n, so that the 2n + 2 rows
// of sums a strip builds beyond its own cost at most half as much again).
constexpr int kSmoothChunk = 64;
int strip_rows(int region) { return std::max(kSmoothChunk, 4 * region); }

// Prefix sums of the padded heights along both diagonals for the rows of one
// strip, kept in a ring of 2n + 3 rows: A(r, x) = P(r, x) + A(r - 1, x - 1)
// ("\") and B(r, x) = P(r, x) + B(r - 1, x + 1) ("/"), P the height in fixed
// point with the nearest edge cell beyond the border. The first row of the
// ring and the columns just outside x in [-n, w + n) hold 0, so a diagonal's
// sum restarts there; only differences along one diagonal are used, which are
// exact whatever the start.
class DiagonalSums {
 public:
  DiagonalSums(const HeightField& dem, int region, int base_row)
      : dem_(dem),
        n_(region),
        base_(base_row),
        ring_(2 * region + 3),
        cols_(dem.width() + 2 * region + 2),
        a_(static_cast<std::size_t>(ring_) * cols_, 0),
        b_(a_.size(), 0),
        filled_(base_row) {}

  // Fills the rows up to `row` (rows are added in order).
  void fill_to(int row) {
    const int w = dem_.width(), h = dem_.height();
    for (int r = filled_ + 1; r <= row; ++r) {
      FixedSum* a = line(a_, r);
      FixedSum* b = line(b_, r);
      const FixedSum* pa = line(a_, r - 1);
      const FixedSum* pb = line(b_, r - 1);
      const int cr = std::clamp(r, 0, h - 1);
      a[0] = 0, b[cols_ - 1] = 0;
      for (int c = 1; c + 1 < cols_; ++c) {
        const FixedSum p = to_fixed(dem_(std::clamp(c - n_ - 1, 0, w - 1), cr));
        a[c] = p + pa[c - 1];
        b[c] = p + pb[c + 1];
      }
      a[cols_ - 1] = 0, b[0] = 0;
    }
    filled_ = std::max(filled_, row);
  }

  // Sums of `len` cells from (x0, r0) down and to the right / left.
  FixedSum down_right(int r0, int x0, int len) const {
    return at(a_, r0 + len - 1, x0 + len - 1) - at(a_, r0 - 1, x0 - 1);
  }
  FixedSum down_left(int r0, int x0, int len) const {
    return at(b_, r0 + len - 1, x0 - len + 1) - at(b_, r0 - 1, x0 + 1);
  }

  // The cells of the diamond at (x, row) that the one at (x - 1, row) lacks
  // (its east edge, ">") less those it has that this one lacks (the west edge
  // of the one at x - 1, "<"): each edge is two diagonal runs,
  //   east:  down_right(row - n, x, n + 1) + down_left(row + 1, x + n - 1, n),
  //   west:  down_left(row - n, x - 1, n + 1) + down_right(row + 1, x - n, n),
  // written out on the three rows they touch (row - n - 1, row, row + n), whose
  // places in the ring are found once a row.
  struct EastStep {
    const FixedSum *a_up, *a_mid, *a_down, *b_up, *b_mid, *b_down;
    int n;
    FixedSum operator()(int x) const {
      return a_mid[x + n] - a_up[x - 1] + b_down[x] - b_mid[x + n] - b_mid[x - 1 - n] + b_up[x] -
             a_down[x - 1] + a_mid[x - n - 1];
    }
  };
  EastStep east_step(int row) const {
    const auto at_row = [&](const std::vector<FixedSum>& t, int r) {
      return &t[static_cast<std::size_t>((r - base_) % ring_) * cols_ + (n_ + 1)];
    };
    return {at_row(a_, row - n_ - 1),
            at_row(a_, row),
            at_row(a_, row + n_),
            at_row(b_, row - n_ - 1),
            at_row(b_, row),
            at_row(b_, row + n_),
            n_};
  }

  // The same from (x, row - 1) to (x, row): south edge "v" less north edge "^".
  FixedSum step_south(int x, int row) const {
    const int n = n_, up = row - 1;
    return down_right(row, x - n, n + 1) + down_left(row, x + n, n) - down_left(up - n, x, n + 1) -
           down_right(up - n + 1, x + 1, n);
  }

 private:
  FixedSum* line(std::vector<FixedSum>& t, int r) {
    return &t[static_cast<std::size_t>((r - base_) % ring_) * cols_];
  }
  FixedSum at(const std::vector<FixedSum>& t, int r, int x) const {
    return t[static_cast<std::size_t>((r - base_) % ring_) * cols_ + (x + n_ + 1)];
  }

  const HeightField& dem_;
  int n_, base_, ring_, cols_;
  std::vector<FixedSum> a_, b_;
  int filled_;
};

// The diamond of L1 radius n at (x, row), its centre included, cell by cell
// (the start of a strip).
FixedSum diamond_direct(const HeightField& dem, int x, int row, int n) {
  FixedSum sum = 0;
  for (int dr = -n; dr <= n; ++dr) {
    const int reach = n - std::abs(dr);
    const int r = std::clamp(row + dr, 0, dem.height() - 1);
    for (int dc = -reach; dc <= reach; ++dc)
      sum += to_fixed(dem(std::clamp(x + dc, 0, dem.width() - 1), r));
  }
  return sum;
}

}  // namespace

// The diamond sums are exact integer sums, so they do not depend on the order
// they are made in: a window of the DEM smooths to the bits the whole DEM
// gives (away from its edges), which the tiled descriptor
// (snow_cover_to_files) relies on, and the O(1) sums below give the bits of
// the direct ones. Each diamond comes from its west neighbour's by adding its
// east edge and taking away the west edge of the other (two diagonal runs
// each, four lookups of the diagonal prefix sums): O(1) a cell whatever n.
// The first column steps south the same way; a strip's first cell is summed
// directly (O(n^2) once a strip of at least 4n rows).
HeightField smooth(const HeightField& dem, int region) {
  const int w = dem.width(), h = dem.height(), n = region;
  HeightField out(w, h, 0.0f, dem.geo());
  const double inv_count = 1.0 / smoothing_neighbour_count(n);
  const int strip = strip_rows(n);
  const int strips = (h + strip - 1) / strip;
  const auto put = [&](int x, int row, FixedSum diamond) {
    const FixedSum sum = diamond - to_fixed(dem(x, row));  // the diamond without its centre
    const double mean = static_cast<double>(sum) / kFixedScale * inv_count;
    out(x, row) = static_cast<float>(0.5 * (dem(x, row) + mean));
  };
  tbb::parallel_for(
      tbb::blocked_range<int>(0, strips, 1),
      [&](const tbb::blocked_range<int>& range) {
        for (int s = range.begin(); s < range.end(); ++s) {
          const int r0 = s * strip, r1 = std::min(h, r0 + strip);
          DiagonalSums sums(dem, n, r0 - n - 1);
          FixedSum first = 0;  // the diamond at (0, row)
          for (int row = r0; row < r1; ++row) {
            sums.fill_to(row + n);
            first = row == r0 ? diamond_direct(dem, 0, row, n) : first + sums.step_south(0, row);
            FixedSum d = first;
            put(0, row, d);
            const auto step_east = sums.east_step(row);
            for (int x = 1; x < w; ++x) {
              d += step_east(x);
              put(x, row, d);
            }
          }
        }
      },
      tbb::simple_partitioner());
  return out;
}

float tsa_at(const HeightField& dem, const terrain::Grid<Vector3f>& normals, int x, int row) {
  const float dx = static_cast<float>(dem.geo().cell_size_x());
  const float dy = static_cast<float>(dem.geo().cell_size_y());
  const Vector3f& N = normals(x, row);
  float best = kInfinity;
  // The far vertices of the 12 triangles are the 8 neighbours.
  for (int dr = -1; dr <= 1; ++dr) {
    for (int dc = -1; dc <= 1; ++dc) {
      if (dr == 0 && dc == 0) continue;
      const int vx = x + dc, vr = row + dr;
      if (vx < 0 || vr < 0 || vx >= dem.width() || vr >= dem.height()) continue;
      const Vector3f P_minus_X = offset(dem, x, row, dc, dr, dx, dy);
      const Vector3f& M = normals(vx, vr);
      // Paper eq. (3): the sphere tangent at X (centre X + tN) that touches
      // the tangent plane (P, M) has t = ((X - P) . M) / (1 - N . M).
      const float denominator = 1.0f - N.dot(M);
      const float numerator = -P_minus_X.dot(M);
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

// Checks of the DEM's shape and georeference, for the whole DEM or a header.
void validate_grid(int width, int height, const terrain::GeoReference& geo, const CoverOptions& o) {
  o.validate();
  require(width >= 3 && height >= 3, "the DEM must be at least 3 x 3 cells");
  require(geo.north_up() && geo.cell_size_x() > 0 && geo.cell_size_y() > 0,
          "the DEM must be north-up with positive cell sizes; warp it with drift import");
  require(!terrain::is_geographic(geo.crs_wkt),
          "the DEM is in degrees; the descriptor needs metres: run drift import first");
  const int n = region_in_cells(o, geo.cell_size_x());
  require(n <= 256, "the smoothing region is " + std::to_string(n) +
                        " cells on this DEM (over 256): lower --region or resample the DEM");
}

std::string nodata_message(std::size_t nodata) {
  return "the DEM has " + std::to_string(nodata) +
         " nodata cells; drift import fills them (run it first)";
}

// Bytes a cell of the grid worked on (the DEM or a window of it) at the
// descriptor's peak, the TSA step: the DEM, the smoothed field and the TSA (4
// each) and the normals (12); later steps hold the DEM, the smoothed field,
// the TSA, t and t smoothed (20). The smoothing's diagonal sums are
// strip-sized (two 16-byte sums a cell of 2n + 3 rows a thread), counted apart.
// Measured: a 3072^2 DEM in blocks of 2048 (windows of 2204^2) peaked 148 MB
// above a 32^2 one, where this counts 140 MB.
constexpr std::uint64_t kCoverBytesPerCell = 24;

std::uint64_t smoothing_bytes(int width, int region) {
  const std::uint64_t threads = std::max(1, tbb::this_task_arena::max_concurrency());
  return threads * (2 * std::uint64_t(region) + 3) * (width + 2 * std::uint64_t(region) + 2) * 32;
}

}  // namespace

int default_cover_block(int halo, std::uint64_t available) {
  constexpr int kTile = 256;
  const auto window_bytes = [&](int block) {
    const std::uint64_t side = std::uint64_t(block) + 2 * std::uint64_t(halo);
    return side * side * kCoverBytesPerCell;
  };
  int block = std::max(kCoverBlock, (4 * halo + kTile - 1) / kTile * kTile);
  while (block > kCoverBlock && window_bytes(block) > available / 2) block -= kTile;
  return block;
}

namespace {

void validate(const HeightField& dem, const CoverOptions& o) {
  validate_grid(dem.width(), dem.height(), dem.geo(), o);
  std::size_t nodata = 0;
  for (float v : dem.values()) nodata += std::isnan(v) ? 1 : 0;
  require(nodata == 0, nodata_message(nodata));
  require_memory(dem.size() * kCoverBytesPerCell +
                     smoothing_bytes(dem.width(), region_in_cells(o, dem.geo().cell_size_x())),
                 "the snow cover of a " + std::to_string(dem.width()) + " x " +
                     std::to_string(dem.height()) + " DEM",
                 "crop or resample the DEM first (drift import --crop, --resample)");
}

bool in_southern_hemisphere(const terrain::GeoReference& geo, int width, int height,
                            Hemisphere hemisphere) {
  if (hemisphere != Hemisphere::Auto) return hemisphere == Hemisphere::South;
  if (geo.crs_wkt.empty()) return false;
  return terrain::centre_lonlat(geo, width, height)[1] < 0.0;
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
// z_max is the whole DEM's highest height (a window's would differ).
HeightField descriptor_from_accessibility(const HeightField& dem, const HeightField& tsa,
                                          const CoverOptions& o, float z_max) {
  const float r = static_cast<float>(radius_in_metres(o, dem.geo().cell_size_x()));
  const float b = static_cast<float>(o.floor);
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
  const Vector3f a = offset(smoothed, x, row, tri[0], tri[1], dx, dy);
  const Vector3f c = offset(smoothed, x, row, tri[2], tri[3], dx, dy);
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

namespace {

// Steps 1-6 on `dem`, the whole DEM or a window of it with a halo
// (snow_cover_to_files): z_max and the hemisphere are the whole DEM's. Every
// step reads the DEM through its own cells and the clamped border only, so a
// window's cells farther than cover_halo from its inner edges get the whole
// DEM's bits.
CoverResult cover_grid(const HeightField& dem, const CoverOptions& o, float z_max, bool southern,
                       const ProgressFn& progress) {
  CoverResult result;
  result.southern = southern;
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
  HeightField t = smooth(descriptor_from_accessibility(dem, result.accessibility, o, z_max), 1);
  // 6. Sun (lines 10-15).
  if (o.sun_range_deg > 0.0) t = apply_sun(t, smoothed, o, result.southern);
  progress(1.0, "");
  result.descriptor = std::move(t);
  return result;
}

}  // namespace

int cover_halo(const CoverOptions& o, double cell_m) {
  // k smoothing passes reach n cells each; the normals (Horn, 3 x 3) and the
  // TSA's neighbour normals 2 more; the smoothing of t 1 more (the sun step
  // reads the smoothed field 1 cell around, within that).
  return o.iterations * region_in_cells(o, cell_m) + 3;
}

CoverResult snow_cover(const HeightField& dem, const CoverOptions& o, const ProgressFn& progress) {
  validate(dem, o);
  float z_max = -kInfinity;
  for (float v : dem.values()) z_max = std::max(z_max, v);
  return cover_grid(dem, o, z_max,
                    in_southern_hemisphere(dem.geo(), dem.width(), dem.height(), o.hemisphere),
                    progress);
}

CoverFilesResult snow_cover_to_files(const CoverFiles& files, const CoverOptions& o,
                                     const ProgressFn& progress) {
  terrain::RasterBlockReader reader(files.dem);
  const int width = reader.width(), height = reader.height();
  const terrain::GeoReference& geo = reader.geo();
  validate_grid(width, height, geo, o);
  const double cell = geo.cell_size_x();
  const int halo = cover_halo(o, cell), n = region_in_cells(o, cell);
  const int block =
      terrain::block_cells(files.block, default_cover_block(halo, available_memory_bytes()));
  // The largest window: a block with its halo on every side.
  const int side_x = std::min(width, block + 2 * halo), side_y = std::min(height, block + 2 * halo);
  const std::uint64_t window_cells = std::uint64_t(side_x) * side_y;
  require_memory(
      window_cells * kCoverBytesPerCell + smoothing_bytes(side_x, n) +
          std::uint64_t(std::min(block, width)) * std::min(block, height) * sizeof(float) +
          kGdalCacheBytes,
      "the snow cover of a " + std::to_string(width) + " x " + std::to_string(height) +
          " DEM in blocks of " + std::to_string(block) + " cells (windows of " +
          std::to_string(side_x) + " x " + std::to_string(side_y) + " with a " +
          std::to_string(halo) + "-cell halo)",
      "give a smaller --block, or a smaller --region or --iterations");
  const int bx_count = (width + block - 1) / block, by_count = (height + block - 1) / block;
  const double blocks = double(bx_count) * by_count;
  // Pass 1: the DEM's highest cell (the altitude factor's z_max) and its
  // nodata, block by block.
  CoverFilesResult result;
  result.width = width, result.height = height, result.block = block, result.halo = halo;
  result.cell_m = cell;
  float z_max = -kInfinity;
  std::size_t nodata = 0;
  for (int j = 0; j < by_count; ++j)
    for (int i = 0; i < bx_count; ++i) {
      const int bx = i * block, by = j * block;
      const std::vector<float> cells =
          reader.read(bx, by, std::min(block, width - bx), std::min(block, height - by));
      for (float v : cells) {
        if (std::isnan(v))
          ++nodata;
        else
          z_max = std::max(z_max, v);
      }
      if (!progress(0.05 * (j * bx_count + i + 1) / blocks, "heights")) throw Cancelled();
    }
  require(nodata == 0, nodata_message(nodata));
  result.southern = in_southern_hemisphere(geo, width, height, o.hemisphere);
  // Pass 2: each block from its window.
  using terrain::RasterBlockWriter;
  std::unique_ptr<RasterBlockWriter> cover, descriptor, accessibility;
  if (!files.cover.empty())
    cover = std::make_unique<RasterBlockWriter>(files.cover, width, height, geo,
                                                terrain::WriteOptions{"snow cover (1 - t)", ""});
  if (!files.descriptor.empty())
    descriptor = std::make_unique<RasterBlockWriter>(
        files.descriptor, width, height, geo,
        terrain::WriteOptions{"snow descriptor t (0 snow, 1 rock)", ""});
  if (!files.accessibility.empty())
    accessibility = std::make_unique<RasterBlockWriter>(
        files.accessibility, width, height, geo,
        terrain::WriteOptions{"tangent sphere accessibility", "m"});
  std::vector<float> out;
  double cover_sum = 0.0;
  for (int j = 0; j < by_count; ++j)
    for (int i = 0; i < bx_count; ++i) {
      const int bx = i * block, by = j * block;
      const int bw = std::min(block, width - bx), bh = std::min(block, height - by);
      const int x0 = std::max(0, bx - halo), y0 = std::max(0, by - halo);
      const int x1 = std::min(width, bx + bw + halo), y1 = std::min(height, by + bh + halo);
      HeightField window(x1 - x0, y1 - y0, 0.0f, geo);
      {
        std::vector<float> cells = reader.read(x0, y0, x1 - x0, y1 - y0);
        std::copy(cells.begin(), cells.end(), window.values().begin());
      }
      auto& gt = window.geo().geotransform;
      gt[0] += x0 * gt[1], gt[3] += y0 * gt[5];
      const double done = 0.05 + 0.95 * (j * bx_count + i) / blocks;
      const CoverResult r = cover_grid(window, o, z_max, result.southern,
                                       scaled_progress(progress, done, done + 0.95 / blocks));
      const auto put = [&](RasterBlockWriter* writer, const HeightField& grid, bool one_minus) {
        if (!writer && !one_minus) return;
        out.resize(static_cast<std::size_t>(bw) * bh);
        double sum = 0.0;
        for (int y = 0; y < bh; ++y) {
          double row_sum = 0.0;
          for (int x = 0; x < bw; ++x) {
            const float v = grid(bx - x0 + x, by - y0 + y);
            const float value = one_minus ? 1.0f - v : v;
            out[static_cast<std::size_t>(y) * bw + x] = value;
            row_sum += value;
          }
          sum += row_sum;
        }
        if (one_minus) cover_sum += sum;
        if (writer) writer->write(bx, by, bw, bh, out.data());
      };
      put(cover.get(), r.descriptor, true);
      put(descriptor.get(), r.descriptor, false);
      put(accessibility.get(), r.accessibility, false);
    }
  for (auto* writer : {cover.get(), descriptor.get(), accessibility.get()})
    if (writer) writer->finish();
  result.mean_cover = cover_sum / (double(width) * height);
  progress(1.0, "");
  return result;
}

}  // namespace drift::snow
