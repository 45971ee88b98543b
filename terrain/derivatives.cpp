#include "terrain/angles.h"
#include "terrain/derivatives.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "terrain/error.h"

namespace drift::terrain {
namespace {

constexpr float kDegrees = static_cast<float>(degrees(1.0));  // float per radian

void require_metric_cells(const HeightField& dem) {
  const auto& g = dem.geo();
  if (!g.north_up() || !(g.cell_size_x() > 0) || !(g.cell_size_y() > 0)) {
    throw Error("slope, aspect and normals need a north-up raster with positive cell sizes; " +
                std::string("reproject it with `drift import`"));
  }
}

}  // namespace

Gradient horn_gradient(const HeightField& dem, int x, int row) {
  return horn_gradient([&](int xx, int rr) { return dem(xx, rr); }, dem.width(), dem.height(),
                       static_cast<float>(dem.geo().cell_size_x()),
                       static_cast<float>(dem.geo().cell_size_y()), x, row);
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
