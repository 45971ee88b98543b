#include "render/normal_map.h"

#include <algorithm>
#include <cmath>

#include "terrain/bilinear.h"
#include "terrain/error.h"

namespace drift::render {

using Eigen::Vector2f;

SlopePyramid::SlopePyramid(const terrain::HeightField& tile, double texel_metres)
    : texel_(texel_metres) {
  if (tile.width() < 2 || tile.height() < 2)
    throw Error("a bump-map tile needs at least 2 x 2 cells");
  if (!(texel_metres > 0)) throw Error("a bump-map texel size must be positive");
  for (float v : tile.values()) {
    if (!std::isfinite(v)) throw Error("a bump-map tile must not hold nodata");
  }
  // Level 0: periodic central differences; u east (columns), v north (rows run south).
  terrain::Grid<Vector2f> base(tile.width(), tile.height(), Vector2f::Zero());
  const float inv = static_cast<float>(0.5 / texel_metres);
  for (int row = 0; row < tile.height(); ++row) {
    for (int x = 0; x < tile.width(); ++x) {
      base(x, row) = Vector2f((tile.wrapped(x + 1, row) - tile.wrapped(x - 1, row)) * inv,
                              (tile.wrapped(x, row - 1) - tile.wrapped(x, row + 1)) * inv);
    }
  }
  terrain::Grid<float> second(tile.width(), tile.height(), 0.0f);
  for (std::size_t i = 0; i < base.size(); ++i) second.values()[i] = base.values()[i].squaredNorm();
  levels_.push_back(std::move(base));
  second_.push_back(std::move(second));
  while (levels_.back().width() > 1 || levels_.back().height() > 1) {
    levels_.push_back(halve_periodic(levels_.back()));
    second_.push_back(halve_periodic(second_.back()));
  }
}

namespace {

// Sums run in double: slopes as Vector2d, moments as double.
double widen(float v) { return v; }
Eigen::Vector2d widen(const Vector2f& v) { return v.cast<double>(); }
float narrow(double v) { return static_cast<float>(v); }
Vector2f narrow(const Eigen::Vector2d& v) { return v.cast<float>(); }

}  // namespace

template <class T>
terrain::Grid<T> halve_periodic(const terrain::Grid<T>& level) {
  const int w = std::max(1, level.width() / 2), h = std::max(1, level.height() / 2);
  // Eigen vectors are not zeroed by T{}.
  T zero{};
  if constexpr (requires { T::Zero(); }) zero = T::Zero();
  terrain::Grid<T> out(w, h, zero);
  // Each coarse texel averages the fine texels it covers: 2x2, or the whole
  // span when a side is odd (a 5-wide level becomes 2 texels of 2.5 each).
  const double sx = static_cast<double>(level.width()) / w;
  const double sy = static_cast<double>(level.height()) / h;
  for (int row = 0; row < h; ++row) {
    for (int x = 0; x < w; ++x) {
      auto sum = widen(zero);
      double weight = 0.0;
      const double x0 = x * sx, x1 = (x + 1) * sx, y0 = row * sy, y1 = (row + 1) * sy;
      for (int fy = static_cast<int>(std::floor(y0)); fy < static_cast<int>(std::ceil(y1)); ++fy) {
        const double wy = std::min<double>(fy + 1, y1) - std::max<double>(fy, y0);
        for (int fx = static_cast<int>(std::floor(x0)); fx < static_cast<int>(std::ceil(x1));
             ++fx) {
          const double wx = std::min<double>(fx + 1, x1) - std::max<double>(fx, x0);
          sum += widen(level.wrapped(fx, fy)) * (wx * wy);
          weight += wx * wy;
        }
      }
      out(x, row) = narrow(decltype(sum)(sum / weight));
    }
  }
  return out;
}

template terrain::Grid<Vector2f> halve_periodic(const terrain::Grid<Vector2f>&);
template terrain::Grid<float> halve_periodic(const terrain::Grid<float>&);

namespace {

// Bilinear sample of a periodic level of a tile `tile_x` x `tile_y` metres at
// (u east, v north).
template <class T>
T bilinear(const terrain::Grid<T>& g, double tile_x, double tile_y, double u, double v) {
  // Texel centres sit at (k + 0.5) * size; v runs north, rows south.
  const double size_x = tile_x / g.width(), size_y = tile_y / g.height();
  const double fx = u / size_x - 0.5, fr = -v / size_y - 0.5;
  const double x0 = std::floor(fx), r0 = std::floor(fr);
  const float tx = static_cast<float>(fx - x0), tr = static_cast<float>(fr - r0);
  // Wrap in double first: u and v may be large (UTM metres).
  const int xi = static_cast<int>(x0 - g.width() * std::floor(x0 / g.width()));
  const int ri = static_cast<int>(r0 - g.height() * std::floor(r0 / g.height()));
  return terrain::bilinear_blend(g.wrapped(xi, ri), g.wrapped(xi + 1, ri), g.wrapped(xi, ri + 1),
                                 g.wrapped(xi + 1, ri + 1), tx, tr);
}

}  // namespace

Vector2f SlopePyramid::sample_level(int i, double u, double v) const {
  return bilinear(levels_[static_cast<std::size_t>(i)], tile_metres_x(), tile_metres_y(), u, v);
}

void SlopePyramid::choose_level(double footprint_metres, int& lo, float& t) const {
  // Level whose texel matches the footprint: log2(footprint / texel), clamped.
  const double lod =
      std::clamp(std::log2(std::max(footprint_metres, 1e-30) / texel_), 0.0, levels() - 1.0);
  lo = static_cast<int>(lod);
  t = lo + 1 < levels() ? static_cast<float>(lod - lo) : 0.0f;
}

Vector2f SlopePyramid::sample(double u, double v, double footprint_metres) const {
  int lo = 0;
  float t = 0.0f;
  choose_level(footprint_metres, lo, t);
  Vector2f a = sample_level(lo, u, v);
  if (t <= 0.0f) return a;
  return (1 - t) * a + t * sample_level(lo + 1, u, v);
}

SlopePyramid::Moments SlopePyramid::sample_moments(double u, double v,
                                                   double footprint_metres) const {
  int lo = 0;
  float t = 0.0f;
  choose_level(footprint_metres, lo, t);
  auto second_at = [&](int i) {
    return bilinear(second_[static_cast<std::size_t>(i)], tile_metres_x(), tile_metres_y(), u, v);
  };
  Moments m;
  m.slope = sample(u, v, footprint_metres);
  float e2 = second_at(lo);
  if (t > 0.0f) e2 = (1 - t) * e2 + t * second_at(lo + 1);
  m.variance = std::max(0.0f, e2 - m.slope.squaredNorm());
  return m;
}

}  // namespace drift::render
