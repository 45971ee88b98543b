// Snowfall on the ground block by block (snowfall_blocks.h).
#include "snow/snowfall_blocks.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "snow/adhesion_coverage.h"
#include "snow/occlusion_blocks.h"
#include "snow/snowfall_directions.h"
#include "snow/snowfall_probability.h"
#include "snow/snowfall_scene.h"
#include "snow/stabilise_direct.h"
#include "snow/stabilise_grid.h"
#include "terrain/angles.h"
#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/raster_blocks.h"
#include "terrain/raster_io.h"

namespace drift::snow {

namespace {

// The band at a window's edge where nothing may move (cells): the solver
// reads and writes 8-neighbours, and only the outermost ring of a window
// misses neighbours the whole raster has; a second ring keeps what the
// ring's cells read of their inner neighbours inside the check.
constexpr int kBand = 2;

// Cells [x0, x1) x [y0, y1) of the raster.
struct Rect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  Rect grown(int by, int w, int h) const {
    auto clamp = [](std::int64_t v, int hi) {
      return static_cast<int>(std::clamp<std::int64_t>(v, 0, hi));
    };
    return {clamp(std::int64_t{x0} - by, w), clamp(std::int64_t{y0} - by, h),
            clamp(std::int64_t{x1} + by, w), clamp(std::int64_t{y1} + by, h)};
  }
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  std::size_t cells() const { return static_cast<std::size_t>(width()) * height(); }
  bool operator==(const Rect& o) const {
    return x0 == o.x0 && y0 == o.y0 && x1 == o.x1 && y1 == o.y1;
  }
};

// One bit a raster cell: where a block's accepted run moved snow.
class CellBits {
 public:
  CellBits(int w, int h) : w_(w), bits_((static_cast<std::size_t>(w) * h + 63) / 64, 0) {}
  bool get(int x, int y) const { return (bits_[index(x, y) / 64] >> (index(x, y) % 64)) & 1u; }
  void set(int x, int y, bool v) {
    const std::size_t i = index(x, y);
    bits_[i / 64] =
        (bits_[i / 64] & ~(std::uint64_t{1} << (i % 64))) | (std::uint64_t{v} << (i % 64));
  }

 private:
  std::size_t index(int x, int y) const { return static_cast<std::size_t>(y) * w_ + x; }
  int w_;
  std::vector<std::uint64_t> bits_;
};

// Calls fn(x, y) (raster cells) for the cells of `win` within kBand of its
// edges that are not the raster's, until fn returns true; returns whether it did.
template <class Fn>
bool any_in_band(const Rect& win, int width, int height, const Fn& fn) {
  for (int y = win.y0; y < win.y1; ++y)
    for (int x = win.x0; x < win.x1; ++x) {
      const bool near = (win.x0 > 0 && x < win.x0 + kBand) || (win.y0 > 0 && y < win.y0 + kBand) ||
                        (win.x1 < width && x >= win.x1 - kBand) ||
                        (win.y1 < height && y >= win.y1 - kBand);
      if (near && fn(x, y)) return true;
    }
  return false;
}

// The whole raster's frame (terrain/local_frame.h's, read block by block):
// simulate_snowfall's scene less its ground.
struct Frame {
  float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();
  double x0 = 0, y0 = 0, dx = 1, dy = 1;
  Eigen::Vector3d origin{0, 0, 0};
};

Frame frame_of(const terrain::RasterBlockReader& reader, int block) {
  const terrain::GeoReference& geo = reader.geo();
  if (!geo.north_up() || geo.cell_size_x() <= 0 || geo.cell_size_y() <= 0)
    throw Error(
        "the ground raster must be north-up with positive cell sizes in metres "
        "(run drift import on it first)");
  if (reader.width() < 2 || reader.height() < 2)
    throw Error("the ground raster must be at least 2 x 2 cells");
  Frame f;
  for (int y = 0; y < reader.height(); y += block) {
    const int h = std::min(block, reader.height() - y);
    for (float v : reader.read(0, y, reader.width(), h))
      if (!std::isnan(v)) f.lo = std::min(f.lo, v), f.hi = std::max(f.hi, v);
  }
  if (!std::isfinite(f.lo)) throw Error("the ground raster holds no valid height (all nodata)");
  const auto centre = geo.cell_center((reader.width() - 1) / 2.0, (reader.height() - 1) / 2.0);
  f.origin = Eigen::Vector3d(centre[0], centre[1], static_cast<double>(f.lo));
  const auto nw = geo.cell_center(0, 0);
  f.x0 = nw[0] - f.origin.x(), f.y0 = nw[1] - f.origin.y();
  f.dx = geo.cell_size_x(), f.dy = geo.cell_size_y();
  return f;
}

// A window settled: its ground with the occlusion's halo (raw and as the
// scene holds it), the probability there, and the window's snow at rest with
// the cells the solver touched.
struct Settled {
  Rect win, occ;
  std::vector<float> raw;
  SnowScene part;
  SnowProbability prob;
  terrain::Grid<double> snow;
  std::vector<std::uint8_t> touched;
  double fallen = 0;
  bool at_rest = true;
};

class BlockRun {
 public:
  BlockRun(const terrain::RasterBlockReader& reader, const SnowfallOptions& o)
      : reader_(reader),
        o_(o),
        frame_(frame_of(reader, 256)),
        dirs_(jittered_directions(o.azimuth_deg, o.elevation_deg, o.spread_deg, o.maps, o.seed)),
        amount_(o.rate_m_per_h * o.hours) {
    SnowScene s;
    s.dx = frame_.dx, s.dy = frame_.dy;
    s.ground_lo = 0.0f, s.ground_hi = frame_.hi - frame_.lo;  // as make_snow_scene
    occlusion_halo_ = occlusion_halo_cells(s, dirs_);
  }
  int occlusion_halo() const { return occlusion_halo_; }
  const Frame& frame() const { return frame_; }
  double amount() const { return amount_; }

  // Bytes a window of `win` needs at its peak (held by the caller's memory check).
  std::uint64_t bytes(const Rect& win, int block) const {
    const std::uint64_t occ = win.grown(occlusion_halo_, reader_.width(), reader_.height()).cells();
    const std::uint64_t s = win.cells();
    // raw and scene ground, probability and facing (16 B a cell of the
    // occlusion's window); then either the sweep's shadow surfaces and sums
    // (13) or the window's ground, snow and touched marks (13) and the
    // solver's workspace (46 with layers).
    const std::uint64_t layers = o_.direct_layers > 1 ? 8 : 0;
    return 16 * occ + std::max<std::uint64_t>(13 * occ, (13 + 38 + layers) * s) +
           std::uint64_t(3) * 4 * block * block;
  }

  Settled settle(const Rect& win) const {
    Settled r;
    r.win = win;
    r.occ = win.grown(occlusion_halo_, reader_.width(), reader_.height());
    const Rect& occ = r.occ;
    r.raw = reader_.read(occ.x0, occ.y0, occ.width(), occ.height());
    // As make_snow_scene and ground_probability_in_blocks build it, to the bit.
    SnowScene& part = r.part;
    part.ground = terrain::Grid<float>(occ.width(), occ.height(), 0.0f);
    for (std::size_t i = 0; i < r.raw.size(); ++i) {
      const float v = r.raw[i];
      part.ground.values()[i] = (std::isnan(v) ? frame_.lo : v) - frame_.lo;
    }
    part.x0 = frame_.x0 + occ.x0 * frame_.dx;
    part.y0 = frame_.y0 - occ.y0 * frame_.dy;
    part.dx = frame_.dx, part.dy = frame_.dy;
    part.origin = frame_.origin;
    part.ground_lo = 0.0f, part.ground_hi = frame_.hi - frame_.lo;
    r.prob = snow_probability(part, dirs_, o_.occlusion);
    terrain::Grid<float> ground(win.width(), win.height(), 0.0f);
    r.snow = terrain::Grid<double>(win.width(), win.height(), 0.0);
    const double cell_area = frame_.dx * frame_.dy;
    for (int y = 0; y < win.height(); ++y)
      for (int x = 0; x < win.width(); ++x) {
        const int px = win.x0 - occ.x0 + x, py = win.y0 - occ.y0 + y;
        ground(x, y) = part.ground(px, py);
        r.snow(x, y) = static_cast<double>(r.prob.ground(px, py)) * amount_;
      }
    for (double v : r.snow.values()) r.fallen += v * cell_area;
    settle_at_rest(ground, r.snow, frame_.dx, frame_.dy, terrain::tan_degrees(o_.repose_deg),
                   o_.direct_layers, &r.touched);
    r.at_rest = max_repose_excess(ground, r.snow, frame_.dx, frame_.dy, o_.repose_deg,
                                  o_.ground_tolerance) <= o_.ground_tolerance;
    return r;
  }

 private:
  const terrain::RasterBlockReader& reader_;
  const SnowfallOptions& o_;
  Frame frame_;
  std::vector<FallDirection> dirs_;
  double amount_;
  int occlusion_halo_ = 0;
};

struct Writers {
  std::unique_ptr<terrain::RasterBlockWriter> depth, cover, surface;
};

}  // namespace

SnowfallBlockReport snowfall_to_files(const SnowfallBlockFiles& files,
                                      const SnowfallOptions& options, const ProgressFn& progress) {
  options.validate();
  if (files.block < 1) throw Error("snow fall: the block must be 1 cell or more");
  if (files.halo < 0) throw Error("snow fall: the halo must be 0 cells or more");
  terrain::RasterBlockReader reader(files.ground);
  const int width = reader.width(), height = reader.height();
  const BlockRun run(reader, options);
  SnowfallBlockReport out;
  out.width = width, out.height = height;
  out.block = std::min(files.block, std::max(width, height));
  out.occlusion_halo = run.occlusion_halo();
  const int block = out.block;
  const int first_halo = std::max(files.halo, kBand);
  const int bx_count = (width + block - 1) / block, by_count = (height + block - 1) / block;
  out.blocks = bx_count * by_count;

  Writers w;
  const terrain::GeoReference& geo = reader.geo();
  w.depth = std::make_unique<terrain::RasterBlockWriter>(
      files.depth, width, height, geo, terrain::WriteOptions{"snow depth (m)", "m"});
  if (!files.cover.empty())
    w.cover = std::make_unique<terrain::RasterBlockWriter>(
        files.cover, width, height, geo, terrain::WriteOptions{"snow coverage (0..1)", ""});
  if (!files.surface.empty())
    w.surface = std::make_unique<terrain::RasterBlockWriter>(
        files.surface, width, height, geo,
        terrain::WriteOptions{"snow surface height, ground + depth (m)", "m"});

  // GDAL's block cache (held to 64 MiB, terrain/raster_blocks.h) fills with
  // the outputs' dirty tiles up to that.
  const std::uint64_t gdal_cache = std::min<std::uint64_t>(
      std::uint64_t{64} << 20,
      std::uint64_t(4) * width * height * (1 + !files.cover.empty() + !files.surface.empty()));
  CellBits moved(width, height);  // where the accepted runs moved snow
  std::vector<int> halo_of(static_cast<std::size_t>(out.blocks), first_halo);
  std::vector<double> fallen(halo_of.size(), 0.0), kept(halo_of.size(), 0.0);
  std::vector<char> at_rest(halo_of.size(), 1);
  const double cell_area = run.frame().dx * run.frame().dy;

  // A halo doubled, up to the whole raster.
  const auto doubled = [&](int halo) {
    return static_cast<int>(
        std::min<std::int64_t>(std::int64_t{2} * halo, std::max(width, height)));
  };
  // Settles block k from its halo, doubling it until nothing moved in the
  // band (check 1), and writes its cells.
  auto work = [&](int k) {
    const int i = k % bx_count, j = k / bx_count;
    const Rect blk = Rect{i * block, j * block, std::min(width, (i + 1) * block),
                          std::min(height, (j + 1) * block)};
    for (int& halo = halo_of[k];; halo = doubled(halo)) {
      const Rect win = blk.grown(halo, width, height);
      require_memory(run.bytes(win, block) + std::uint64_t(width) * height / 8 + gdal_cache,
                     "snow fall block by block (a window of " + std::to_string(win.width()) +
                         " x " + std::to_string(win.height()) + " cells)",
                     "give a smaller --block");
      const bool whole = win == Rect{0, 0, width, height};
      Settled s = run.settle(win);
      const auto touched = [&](int x, int y) {
        return s.touched[static_cast<std::size_t>(y - win.y0) * win.width() + (x - win.x0)] != 0;
      };
      if (!whole && any_in_band(win, width, height, touched)) {
        ++out.widened;
        continue;
      }
      const int bw = blk.width(), bh = blk.height();
      std::vector<float> depth(static_cast<std::size_t>(bw) * bh), cover(depth.size()),
          surface(depth.size());
      double sum = 0.0;
      for (int y = 0; y < bh; ++y)
        for (int x = 0; x < bw; ++x) {
          const int rx = blk.x0 + x, ry = blk.y0 + y;
          const int ox = rx - s.occ.x0, oy = ry - s.occ.y0;
          const std::size_t c = static_cast<std::size_t>(y) * bw + x;
          moved.set(rx, ry, touched(rx, ry));
          const float ground = s.raw[static_cast<std::size_t>(oy) * s.occ.width() + ox];
          const double d = s.snow(rx - win.x0, ry - win.y0);
          sum += d * cell_area;
          if (std::isnan(ground)) {  // as write_ground_rasters and lay_on_ground leave it
            depth[c] = cover[c] = surface[c] = std::nanf("");
            continue;
          }
          depth[c] = static_cast<float>(std::max(d, 0.0));
          const double stuck =
              adhesion_coverage(s.part.ground_normal(ox, oy), s.prob.ground_facing(ox, oy),
                                run.amount(), options.coverage);
          cover[c] = static_cast<float>(std::max(thin_coverage(d, options.coverage), stuck));
          surface[c] = ground;
          if (std::isfinite(depth[c])) surface[c] += depth[c];
        }
      // The block's share of what fell and what lies (summed in the block).
      double fell = 0.0;
      for (int y = 0; y < bh; ++y)
        for (int x = 0; x < bw; ++x) {
          const int ox = blk.x0 + x - s.occ.x0, oy = blk.y0 + y - s.occ.y0;
          fell += static_cast<double>(s.prob.ground(ox, oy)) * run.amount() * cell_area;
        }
      fallen[k] = fell, kept[k] = sum, at_rest[k] = s.at_rest;
      w.depth->write(blk.x0, blk.y0, bw, bh, depth.data());
      if (w.cover) w.cover->write(blk.x0, blk.y0, bw, bh, cover.data());
      if (w.surface) w.surface->write(blk.x0, blk.y0, bw, bh, surface.data());
      return;
    }
  };

  // Check 2: snow moved, in the accepted result of the blocks that hold them,
  // at cells of the band of block k's window (snow from outside reaching in).
  auto reached_from_outside = [&](int k) {
    const int i = k % bx_count, j = k / bx_count;
    const Rect blk = Rect{i * block, j * block, std::min(width, (i + 1) * block),
                          std::min(height, (j + 1) * block)};
    const Rect win = blk.grown(halo_of[k], width, height);
    return any_in_band(win, width, height, [&](int x, int y) { return moved.get(x, y); });
  };

  for (int k = 0; k < out.blocks; ++k) {
    work(k);
    if (!progress(0.95 * (k + 1) / out.blocks, "snow fall")) throw Cancelled();
  }
  for (bool again = true; again;) {
    again = false;
    for (int k = 0; k < out.blocks; ++k) {
      if (!reached_from_outside(k)) continue;
      ++out.widened;
      again = true;
      halo_of[k] = doubled(halo_of[k]);
      work(k);
    }
  }
  for (int k = 0; k < out.blocks; ++k) {
    out.largest_halo = std::max(out.largest_halo, halo_of[k]);
    out.windows_widened += halo_of[k] > first_halo;
    out.fallen_volume += fallen[k], out.ground_volume += kept[k];
    out.converged = out.converged && at_rest[k];
  }
  w.depth->finish();
  if (w.cover) w.cover->finish();
  if (w.surface) w.surface->finish();
  progress(1.0, "snow fall");
  return out;
}

}  // namespace drift::snow
