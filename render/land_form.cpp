#include "render/land_form.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "render/procedural_noise.h"
#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::render {

terrain::HeightField topographic_position(const terrain::HeightField& dem, double radius_metres) {
  if (!(radius_metres > 0.0)) throw Error("the topographic position radius must be positive");
  const int w = dem.width(), h = dem.height();
  const std::size_t stride = static_cast<std::size_t>(w) + 1;
  require_memory(stride * (h + 1) * 2 * sizeof(double), "the topographic position index",
                 "crop or resample the DEM");
  // Summed-area tables of heights and of valid cells (row and column 0 zero).
  std::vector<double> sum(stride * (h + 1), 0.0), count(stride * (h + 1), 0.0);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const float v = dem(c, r);
      const bool ok = !std::isnan(v);
      const std::size_t i = (r + 1) * stride + c + 1;
      sum[i] = (ok ? v : 0.0) + sum[i - 1] + sum[i - stride] - sum[i - stride - 1];
      count[i] = (ok ? 1.0 : 0.0) + count[i - 1] + count[i - stride] - count[i - stride - 1];
    }
  }
  const int rx = std::max(1, static_cast<int>(std::lround(radius_metres / dem.geo().cell_size_x())));
  const int ry = std::max(1, static_cast<int>(std::lround(radius_metres / dem.geo().cell_size_y())));
  terrain::HeightField out(w, h, NAN, dem.geo());
  auto box = [&](const std::vector<double>& t, int c0, int r0, int c1, int r1) {
    return t[r1 * stride + c1] - t[r0 * stride + c1] - t[r1 * stride + c0] + t[r0 * stride + c0];
  };
  for (int r = 0; r < h; ++r) {
    const int r0 = std::max(0, r - ry), r1 = std::min(h, r + ry + 1);
    for (int c = 0; c < w; ++c) {
      if (std::isnan(dem(c, r))) continue;
      const int c0 = std::max(0, c - rx), c1 = std::min(w, c + rx + 1);
      const double n = box(count, c0, r0, c1, r1);
      out(c, r) = static_cast<float>(dem(c, r) - box(sum, c0, r0, c1, r1) / n);
    }
  }
  return out;
}

float raggedness(double x, double y) {
  // 6 octaves, Hurst 0.5: a standard deviation of 1/2, so a bound moved by
  // jitter x this stays within about +-jitter.
  constexpr Octaves octaves{800.0, 25.0, 0x7a66ed00u};
  constexpr float amplitude = 0.5f / (kNoiseStd * 1.4036f);  // sqrt(1.97)
  return filtered_noise(x, y, octaves, amplitude, 0.5f, 0.0).value;
}

}  // namespace drift::render
