#include "snow/occlusion_horizon.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace drift::snow {

namespace {

constexpr float kNone = -std::numeric_limits<float>::infinity();

// Transposes `in` (w x h, row-major) into `out` (h x w).
void transpose(const float* in, float* out, int w, int h) {
  constexpr int B = 64;
  tbb::parallel_for(tbb::blocked_range<int>(0, (h + B - 1) / B), [&](const auto& r) {
    for (int bj = r.begin(); bj < r.end(); ++bj)
      for (int bi = 0; bi < w; bi += B)
        for (int j = bj * B; j < std::min(h, (bj + 1) * B); ++j)
          for (int i = bi; i < std::min(w, bi + B); ++i)
            out[static_cast<std::size_t>(i) * h + j] = in[static_cast<std::size_t>(j) * w + i];
  });
}

// Sweeps `lines` lines of `n` values: line l's upstream line is l - 1 (forward) or
// l + 1; the ray from element k crosses the upstream line at k + shift, `drop`
// lower. Elements are independent within a line, so the result does not depend on
// how the parallel loop splits them.
void sweep(const float* h, float* s, int lines, int n, bool forward, double shift, double drop) {
  const int first = forward ? 0 : lines - 1, step = forward ? 1 : -1;
  std::copy(h + static_cast<std::size_t>(first) * n, h + static_cast<std::size_t>(first + 1) * n,
            s + static_cast<std::size_t>(first) * n);
  for (int l = first + step; l >= 0 && l < lines; l += step) {
    const float* up = s + static_cast<std::size_t>(l - step) * n;
    const float* hl = h + static_cast<std::size_t>(l) * n;
    float* sl = s + static_cast<std::size_t>(l) * n;
    tbb::parallel_for(tbb::blocked_range<int>(0, n, 2048), [&](const auto& r) {
      for (int k = r.begin(); k < r.end(); ++k) {
        const double x = k + shift;
        float upstream = kNone;
        if (x >= 0.0 && x <= n - 1) {
          const int k0 = std::min(static_cast<int>(x), n - 2 < 0 ? 0 : n - 2);
          const double t = x - k0;
          const double v = n == 1 ? up[0] : up[k0] * (1.0 - t) + up[k0 + 1] * t;
          upstream = static_cast<float>(v - drop);
        }
        sl[k] = std::max(hl[k], upstream);
      }
    });
  }
}

}  // namespace

ShadowSurface HorizonSweeper::shadow(const Eigen::Vector3d& toward_source) {
  const int w = heights_.width(), h = heights_.height();
  ShadowSurface out;
  const double horizontal = std::hypot(toward_source.x(), toward_source.y());
  if (horizontal < 1e-9 || w == 0 || h == 0) {
    out.s = heights_;
    return out;
  }
  const double tan_el = toward_source.z() / horizontal;
  // Grid steps per metre along the horizontal direction to the source.
  const double dcol = toward_source.x() / horizontal / dx_;
  const double drow = -toward_source.y() / horizontal / dy_;
  if (std::abs(drow) >= std::abs(dcol)) {
    // Lines are rows (contiguous): one row upstream per step.
    const double metres = 1.0 / std::abs(drow);
    out.s = terrain::Grid<float>(w, h);
    sweep(heights_.data(), out.s.data(), h, w, drow <= 0, dcol * metres, metres * tan_el);
  } else {
    const double metres = 1.0 / std::abs(dcol);
    if (transposed_.empty()) {
      transposed_ = terrain::Grid<float>(h, w);
      transpose(heights_.data(), transposed_.data(), w, h);
    }
    out.s = terrain::Grid<float>(h, w);
    out.transposed = true;
    sweep(transposed_.data(), out.s.data(), w, h, dcol <= 0, drow * metres, metres * tan_el);
  }
  return out;
}

}  // namespace drift::snow
