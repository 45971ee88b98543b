// A 2-D raster of values with its georeference: the plain data type that every
// stage reads and writes (a height field is Grid<float>).
//
// Layout follows GDAL: row-major, column x in [0, width) running east, row in
// [0, height) running *south* (row 0 is the northern edge for a north-up raster).
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace drift::terrain {

// GDAL's affine geotransform, CRS as WKT (empty for a local, unreferenced grid)
// and the nodata value the source declared (cells holding it are invalid).
struct GeoReference {
  // X_geo = gt[0] + col * gt[1] + row * gt[2];  Y_geo = gt[3] + col * gt[4] + row * gt[5]
  std::array<double, 6> geotransform{0.0, 1.0, 0.0, 0.0, 0.0, -1.0};
  std::string crs_wkt;
  std::optional<double> nodata;

  double cell_size_x() const { return geotransform[1]; }
  double cell_size_y() const { return -geotransform[5]; }  // positive for north-up
  bool north_up() const { return geotransform[2] == 0.0 && geotransform[4] == 0.0; }
  // Georeferenced coordinates of the centre of cell (col, row).
  std::array<double, 2> cell_center(double col, double row) const {
    return {geotransform[0] + (col + 0.5) * geotransform[1] + (row + 0.5) * geotransform[2],
            geotransform[3] + (col + 0.5) * geotransform[4] + (row + 0.5) * geotransform[5]};
  }
};

// A local grid with square cells of `cell_size` metres, origin at (0, 0) in the NW corner.
inline GeoReference local_georeference(double cell_size) {
  GeoReference g;
  g.geotransform = {0.0, cell_size, 0.0, 0.0, 0.0, -cell_size};
  return g;
}

template <class T>
class Grid {
 public:
  Grid() = default;
  Grid(int width, int height, T fill = T{}, GeoReference geo = {})
      : width_(width),
        height_(height),
        data_(checked_size(width, height), fill),
        geo_(std::move(geo)) {}

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t size() const { return data_.size(); }
  bool empty() const { return data_.empty(); }

  T& operator()(int x, int row) {
    assert(x >= 0 && x < width_ && row >= 0 && row < height_);
    return data_[static_cast<std::size_t>(row) * width_ + x];
  }
  const T& operator()(int x, int row) const {
    assert(x >= 0 && x < width_ && row >= 0 && row < height_);
    return data_[static_cast<std::size_t>(row) * width_ + x];
  }
  // Clamped access: edges repeat (for finite differences at the border).
  const T& clamped(int x, int row) const {
    return (*this)(std::clamp(x, 0, width_ - 1), std::clamp(row, 0, height_ - 1));
  }
  // Periodic access: the grid tiles the plane (dunes, ripples).
  const T& wrapped(int x, int row) const {
    return (*this)(((x % width_) + width_) % width_, ((row % height_) + height_) % height_);
  }

  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  std::vector<T>& values() { return data_; }
  const std::vector<T>& values() const { return data_; }

  GeoReference& geo() { return geo_; }
  const GeoReference& geo() const { return geo_; }

 private:
  static std::size_t checked_size(int w, int h) {
    assert(w >= 0 && h >= 0);
    return static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  }

  int width_ = 0;
  int height_ = 0;
  std::vector<T> data_;
  GeoReference geo_;
};

using HeightField = Grid<float>;

// A periodic (tileable) north-up grid repeated `times` x `times` around itself:
// the original keeps its georeference in the middle tile (`times` odd).
template <class T>
Grid<T> repeat_periodic(const Grid<T>& tile, int times) {
  assert(times >= 1 && times % 2 == 1);
  GeoReference geo = tile.geo();
  const int half = times / 2;
  geo.geotransform[0] -= half * tile.width() * geo.geotransform[1];
  geo.geotransform[3] -= half * tile.height() * geo.geotransform[5];
  Grid<T> out(tile.width() * times, tile.height() * times, T{}, geo);
  for (int row = 0; row < out.height(); ++row)
    for (int x = 0; x < out.width(); ++x) out(x, row) = tile(x % tile.width(), row % tile.height());
  return out;
}

}  // namespace drift::terrain
