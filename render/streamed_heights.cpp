#include "render/streamed_heights.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "terrain/error.h"
#include "terrain/raster_blocks.h"

namespace drift::render {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr std::uint64_t kGdalCache = std::uint64_t{64} << 20;  // RasterBlockReader's cap

// One GDAL dataset a thread (a GDALDataset is not thread-safe).
class Readers {
 public:
  explicit Readers(const std::filesystem::path& path) : path_(path) {}
  terrain::RasterBlockReader& local() {
    std::unique_ptr<terrain::RasterBlockReader>& r = readers_.local();
    if (!r) r = std::make_unique<terrain::RasterBlockReader>(path_);
    return *r;
  }

 private:
  std::filesystem::path path_;
  tbb::enumerable_thread_specific<std::unique_ptr<terrain::RasterBlockReader>> readers_;
};

// A strip of block rows [by0, by1) read, converted, quantised and decoded.
struct Strip {
  int by0 = 0, by1 = 0;
  int r0 = 0, r1 = 0;    // its vertex rows [r0, r1)
  std::vector<float> z;  // decoded heights, row-major
  float lo = kInf, hi = -kInf;
  std::size_t lo_at = 0, hi_at = 0;  // the first in row-major order
};

}  // namespace

std::uint64_t streamed_heights_bytes(int width, int height, int threads) {
  const std::uint64_t cells = static_cast<std::uint64_t>(width) * height;
  const std::uint64_t blocks =
      static_cast<std::uint64_t>((width - 2) / QuantisedHeights::kBlock + 1) *
      ((height - 2) / QuantisedHeights::kBlock + 1);
  // Strips in flight: the pipeline's tokens (threads + 1), each a strip of
  // floats and GDAL's buffer of it.
  const std::uint64_t strip = static_cast<std::uint64_t>(width) *
                              std::min(kStripRows + QuantisedHeights::kBlock, height) *
                              sizeof(float);
  return cells * sizeof(std::uint16_t) + blocks * sizeof(QuantisedHeights::Range) +
         strip * (static_cast<std::uint64_t>(threads) + 1) +
         std::min(cells * sizeof(float), kGdalCache);
}

StreamedHeights read_streamed_heights(const std::filesystem::path& dem, float k, int strip_rows) {
  Readers readers(dem);
  terrain::RasterBlockReader& first = readers.local();
  const int w = first.width(), h = first.height();
  const std::string name = "the terrain raster '" + dem.string() + "'";
  if (w < 2 || h < 2)
    throw Error(name + " must be at least 2 x 2 cells, got " + std::to_string(w) + " x " +
                std::to_string(h));
  StreamedHeights out;
  out.geo = first.geo();
  const terrain::GeoReference& geo = out.geo;
  if (!geo.north_up()) throw Error(name + " is rotated; warp it north-up first (drift import)");
  if (!(geo.cell_size_x() > 0) || !(geo.cell_size_y() > 0))
    throw Error(name + "'s cell size must be positive (north-up, metres)");
  out.heights = QuantisedHeights(w, h);
  QuantisedHeights& q = out.heights;
  const int block_rows_a_strip = std::max(1, strip_rows / QuantisedHeights::kBlock);
  const int strips = (q.block_rows() + block_rows_a_strip - 1) / block_rows_a_strip;
  const auto span = [&](int s) {
    Strip t;
    t.by0 = s * block_rows_a_strip;
    t.by1 = std::min(t.by0 + block_rows_a_strip, q.block_rows());
    t.r0 = q.block_row_first(t.by0);
    t.r1 = q.block_row_end(t.by1 - 1);
    return t;
  };

  // Pass 1: the lowest valid height (exact, so the same whatever the strips).
  const float lo = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, strips, 1), kInf,
      [&](const tbb::blocked_range<int>& range, float m) {
        for (int s = range.begin(); s != range.end(); ++s) {
          const Strip t = span(s);
          for (const float v : readers.local().read(0, t.r0, w, t.r1 - t.r0))
            if (!std::isnan(v)) m = std::min(m, v);
        }
        return m;
      },
      [](float a, float b) { return std::min(a, b); });
  if (!std::isfinite(lo)) throw Error(name + " holds no valid height (all nodata)");

  // The local frame as terrain::local_frame and TerrainScene::fill_heights
  // give it in core.
  const auto centre = geo.cell_center((w - 1) / 2.0, (h - 1) / 2.0);
  out.origin =
      Eigen::Vector3d(centre[0], centre[1], static_cast<double>(lo) * static_cast<double>(k));
  const auto nw = geo.cell_center(0, 0);
  HeightGrid& frame = out.frame;
  frame.width = w;
  frame.height = h;
  frame.x0 = static_cast<float>(nw[0] - out.origin.x());
  frame.y0 = static_cast<float>(nw[1] - out.origin.y());
  frame.dx = static_cast<float>(geo.cell_size_x());
  frame.dy = static_cast<float>(geo.cell_size_y());
  const float z0 = static_cast<float>(out.origin.z());

  // Pass 2: strips read side by side (at most a token a thread and one
  // more), each converted, its extremes found on the floats (as fill_heights
  // finds them), its block rows quantised and its heights decoded; the
  // strips' extremes and sums are then taken in order, row-major as the
  // floats of the whole DEM would be.
  float hi_v = -kInf, lo_v = kInf;
  std::size_t hi_at = 0, lo_at = 0;
  double sum = 0.0, sum_squares = 0.0;
  int next = 0;
  const std::size_t tokens = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()) + 1;
  tbb::parallel_pipeline(
      tokens, tbb::make_filter<void, int>(tbb::filter_mode::serial_in_order,
                                          [&](tbb::flow_control& fc) {
                                            if (next == strips) {
                                              fc.stop();
                                              return 0;
                                            }
                                            return next++;
                                          }) &
                  tbb::make_filter<int, std::shared_ptr<Strip>>(
                      tbb::filter_mode::parallel,
                      [&](int s) {
                        auto t = std::make_shared<Strip>(span(s));
                        t->z = readers.local().read(0, t->r0, w, t->r1 - t->r0);
                        const std::size_t base = static_cast<std::size_t>(t->r0) * w;
                        for (std::size_t i = 0; i < t->z.size(); ++i) {
                          float& v = t->z[i];
                          const float hv = std::isnan(v) ? lo : v;
                          v = hv * k - z0;
                          if (v > t->hi) t->hi = v, t->hi_at = base + i;
                          if (v < t->lo) t->lo = v, t->lo_at = base + i;
                        }
                        for (int by = t->by0; by < t->by1; ++by)
                          q.quantise_block_row(
                              by, t->z.data() +
                                      static_cast<std::size_t>(q.block_row_first(by) - t->r0) * w);
                        for (int r = t->r0; r < t->r1; ++r)
                          for (int c = 0; c < w; ++c)
                            t->z[static_cast<std::size_t>(r - t->r0) * w + c] = q.at(c, r);
                        return t;
                      }) &
                  tbb::make_filter<std::shared_ptr<Strip>, void>(
                      tbb::filter_mode::serial_in_order, [&](const std::shared_ptr<Strip>& t) {
                        if (t->hi > hi_v)
                          hi_v = t->hi, hi_at = t->hi_at;  // strictly: the first wins
                        if (t->lo < lo_v) lo_v = t->lo, lo_at = t->lo_at;
                        for (const float z : t->z) sum += z, sum_squares += double(z) * z;
                      }));
  out.sum = sum;
  out.sum_squares = sum_squares;
  const auto vertex = [&](std::size_t i, float v) {
    return Eigen::Vector3f(frame.x(static_cast<int>(i % w)), frame.y(static_cast<int>(i / w)), v);
  };
  out.highest = vertex(hi_at, hi_v);
  out.lowest = vertex(lo_at, lo_v);
  return out;
}

}  // namespace drift::render
