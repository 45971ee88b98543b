#include "render/land_form.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "render/material.h"
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
  const int rx =
      std::max(1, static_cast<int>(std::lround(radius_metres / dem.geo().cell_size_x())));
  const int ry =
      std::max(1, static_cast<int>(std::lround(radius_metres / dem.geo().cell_size_y())));
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

namespace {

// The standard normal quantile (Acklam's rational approximation, |error| <
// 1.2e-9 in the central region used here): the threshold of a roughly
// Gaussian field above which it lies a share 1 - p of the ground.
double normal_quantile(double p) {
  p = std::clamp(p, 1e-6, 1.0 - 1e-6);
  const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                      1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                      6.680131188771972e+01, -1.328068155288572e+01};
  const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                      -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                      3.754408661907416e+00};
  if (p < 0.02425 || p > 1.0 - 0.02425) {
    const double q = std::sqrt(-2.0 * std::log(p < 0.5 ? p : 1.0 - p));
    const double x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
                     ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    return p < 0.5 ? x : -x;
  }
  const double q = p - 0.5, r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
}

}  // namespace

float clump_mask(double x, double y, float size, float cover, std::uint64_t seed,
                 double footprint) {
  if (cover <= 0.0f) return 0.0f;
  if (cover >= 1.0f) return 1.0f;
  // Past two clump sizes per footprint the pattern is gone: its mean alone.
  const float keep =
      footprint > 0.0 ? static_cast<float>(std::clamp(size / footprint - 1.0, 0.0, 1.0)) : 1.0f;
  if (keep <= 0.0f) return cover;
  // Three octaves (size, size / 2, size / 4; Hurst 0.5), normalised to a
  // standard deviation of 1: round blobs with ragged edges.
  const Octaves octaves{size, size / 4.0, seed};
  constexpr float kStd = kNoiseStd * 1.3229f;  // sqrt(1 + 1/2 + 1/4)
  const float z = filtered_noise(x, y, octaves, 1.0f / kStd, 0.5f, 0.0).value;
  const float threshold = static_cast<float>(normal_quantile(1.0 - cover));
  // Soft edges a tenth of a standard deviation wide.
  const float inside = smoothstep(threshold - 0.1f, threshold + 0.1f, z);
  return keep * inside + (1.0f - keep) * cover;
}

float raggedness(double x, double y, double footprint) {
  // 6 octaves, Hurst 0.5: a standard deviation of 1/2, so a bound moved by
  // jitter x this stays within about +-jitter.
  constexpr Octaves octaves{800.0, 25.0, 0x7a66ed00u};
  constexpr float amplitude = 0.5f / (kNoiseStd * 1.4036f);  // sqrt(1.97)
  return filtered_noise(x, y, octaves, amplitude, 0.5f, footprint).value;
}

}  // namespace drift::render
