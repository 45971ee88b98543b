#include "terrain/derivatives.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "terrain/error.h"

namespace drift::terrain {
namespace {

constexpr float kDegrees = static_cast<float>(180.0 / std::numbers::pi);

void require_metric_cells(const HeightField& dem) {
  const auto& g = dem.geo();
  if (!g.north_up() || !(g.cell_size_x() > 0) || !(g.cell_size_y() > 0)) {
    throw Error("slope, aspect and normals need a north-up raster with positive cell sizes; " +
                std::string("reproject it with `drift import`"));
  }
}

}  // namespace

Gradient horn_gradient(const HeightField& dem, int x, int row) {
  const float centre = dem(x, row);
  if (std::isnan(centre)) return {NAN, NAN};
  // z(dx, dr): the neighbour's height. Beyond the border it is extrapolated
  // linearly from the two nearest cells in its column (rows beyond) or row
  // (columns beyond), the column clamped first; a nodata neighbour, or one
  // extrapolated from nodata, takes the centre's height. These are exactly
  // gdaldem's -compute_edges rules, so the results agree at the border too.
  const int width = dem.width(), height = dem.height();
  auto valid_or_centre = [&](float v) { return std::isnan(v) ? centre : v; };
  auto z = [&](int dx, int dr) {
    int xx = x + dx;
    const int rr = row + dr;
    if (rr < 0 || rr >= height) {
      xx = std::clamp(xx, 0, width - 1);
      const int edge = rr < 0 ? 0 : height - 1;
      const int inner = rr < 0 ? std::min(1, height - 1) : std::max(height - 2, 0);
      return valid_or_centre(2 * dem(xx, edge) - dem(xx, inner));
    }
    if (xx < 0 || xx >= width) {
      const int edge = xx < 0 ? 0 : width - 1;
      const int inner = xx < 0 ? std::min(1, width - 1) : std::max(width - 2, 0);
      return valid_or_centre(2 * dem(edge, rr) - dem(inner, rr));
    }
    return valid_or_centre(dem(xx, rr));
  };
  // Horn (1981): a b c / d e f / g h i with row -1 (a b c) to the north.
  const float a = z(-1, -1), b = z(0, -1), c = z(1, -1);
  const float d = z(-1, 0), f = z(1, 0);
  const float g = z(-1, 1), h = z(0, 1), i = z(1, 1);
  const float ew = static_cast<float>(dem.geo().cell_size_x());
  const float ns = static_cast<float>(dem.geo().cell_size_y());
  return {((c + 2 * f + i) - (a + 2 * d + g)) / (8 * ew),
          ((a + 2 * b + c) - (g + 2 * h + i)) / (8 * ns)};
}

namespace {
// Applies `cell(x, row)` to every cell in parallel rows, into a grid with
// `dem`'s georeference.
template <class T, class Fn>
Grid<T> per_cell(const HeightField& dem, Fn cell) {
  require_metric_cells(dem);
  // Eigen vectors are not zeroed by T{}: start from a real zero.
  T zero{};
  if constexpr (requires { T::Zero(); }) zero = T::Zero();
  Grid<T> out(dem.width(), dem.height(), zero, dem.geo());
  tbb::parallel_for(0, dem.height(), [&](int row) {
    for (int x = 0; x < dem.width(); ++x) out(x, row) = cell(x, row);
  });
  return out;
}
}  // namespace

Grid<Gradient> gradient(const HeightField& dem) {
  return per_cell<Gradient>(dem, [&](int x, int row) { return horn_gradient(dem, x, row); });
}

Grid<Eigen::Vector3f> normals(const HeightField& dem, float z_scale) {
  return per_cell<Eigen::Vector3f>(dem, [&](int x, int row) {
    const Gradient g = horn_gradient(dem, x, row);
    if (std::isnan(g.dzdx)) return Eigen::Vector3f(0, 0, 1);
    return Eigen::Vector3f(-g.dzdx * z_scale, -g.dzdy * z_scale, 1.0f).normalized();
  });
}

HeightField slope_degrees(const HeightField& dem) {
  auto out = per_cell<float>(dem, [&](int x, int row) {
    const Gradient g = horn_gradient(dem, x, row);
    return std::atan(std::hypot(g.dzdx, g.dzdy)) * kDegrees;
  });
  out.geo().nodata = std::nullopt;
  return out;
}

HeightField aspect_degrees(const HeightField& dem) {
  auto out = per_cell<float>(dem, [&](int x, int row) {
    const Gradient g = horn_gradient(dem, x, row);
    if (std::isnan(g.dzdx) || (g.dzdx == 0.0f && g.dzdy == 0.0f)) return NAN;
    // Downhill is -gradient; its azimuth clockwise from north is atan2(east, north).
    float azimuth = std::atan2(-g.dzdx, -g.dzdy) * kDegrees;
    if (azimuth < 0.0f) azimuth += 360.0f;
    return azimuth >= 360.0f ? 0.0f : azimuth;
  });
  out.geo().nodata = std::nullopt;
  return out;
}

HeightField halve(const HeightField& grid) {
  const int w = (grid.width() + 1) / 2, h = (grid.height() + 1) / 2;
  GeoReference geo = grid.geo();
  for (int k : {1, 2, 4, 5}) geo.geotransform[k] *= 2.0;
  HeightField out(w, h, NAN, geo);
  tbb::parallel_for(0, h, [&](int row) {
    for (int x = 0; x < w; ++x) {
      float sum = 0.0f;
      int count = 0;
      for (int dr = 0; dr < 2; ++dr) {
        for (int dx = 0; dx < 2; ++dx) {
          const int xx = 2 * x + dx, rr = 2 * row + dr;
          if (xx >= grid.width() || rr >= grid.height()) continue;
          const float v = grid(xx, rr);
          if (!std::isnan(v)) sum += v, ++count;
        }
      }
      if (count > 0) out(x, row) = sum / static_cast<float>(count);
    }
  });
  return out;
}

std::vector<HeightField> pyramid(const HeightField& dem, int min_size) {
  std::vector<HeightField> levels{dem};
  while (std::max(levels.back().width(), levels.back().height()) > std::max(min_size, 1)) {
    levels.push_back(halve(levels.back()));
  }
  return levels;
}

}  // namespace drift::terrain
