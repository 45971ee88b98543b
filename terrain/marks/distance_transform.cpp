#include "terrain/marks/distance_transform.h"

#include <cmath>
#include <limits>

namespace drift::marks {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// One dimension of Felzenszwalb & Huttenlocher (2012), algorithm DT(f): the
// squared distance d(p) = min_q (s (p - q))^2 + f(q) over n samples of spacing
// s, in place (stride apart in `f`). Samples with f = inf never lie on the
// lower envelope and are skipped, so an all-infinite line stays infinite.
void squared_distance_1d(double* f, int n, int stride, double s, std::vector<double>& g,
                         std::vector<int>& v, std::vector<double>& z) {
  g.resize(n), v.resize(n), z.resize(n + 1);
  for (int i = 0; i < n; ++i) g[i] = f[static_cast<std::ptrdiff_t>(i) * stride];
  int k = -1;
  auto key = [&](int q) { return g[q] + (s * q) * (s * q); };
  for (int q = 0; q < n; ++q) {
    if (!std::isfinite(g[q])) continue;
    // Where the parabola of q overtakes that of the envelope's last one.
    while (k >= 0) {
      const double x = (key(q) - key(v[k])) / (2.0 * s * s * (q - v[k]));
      if (x > z[k]) {
        z[k + 1] = x;
        break;
      }
      --k;
    }
    ++k;
    v[k] = q;
    if (k == 0) z[0] = -kInf;
    z[k + 1] = kInf;
  }
  if (k < 0) return;  // no finite sample: the line stays infinite
  int j = 0;
  for (int p = 0; p < n; ++p) {
    while (z[j + 1] < p) ++j;
    const double d = s * (p - v[j]);
    f[static_cast<std::ptrdiff_t>(p) * stride] = d * d + g[v[j]];
  }
}

}  // namespace

std::vector<double> euclidean_distance(const std::vector<char>& source, int width, int height,
                                       double dx, double dy, bool edge_is_source) {
  // Padded by one cell on every side when the edge counts as a source.
  const int pad = edge_is_source ? 1 : 0, w = width + 2 * pad, h = height + 2 * pad;
  std::vector<double> d(static_cast<std::size_t>(w) * h, kInf);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int sx = x - pad, sy = y - pad;
      const bool edge = sx < 0 || sy < 0 || sx >= width || sy >= height;
      if (edge || source[static_cast<std::size_t>(sy) * width + sx])
        d[static_cast<std::size_t>(y) * w + x] = 0.0;
    }
  std::vector<double> g, z;
  std::vector<int> v;
  for (int x = 0; x < w; ++x) squared_distance_1d(&d[x], h, w, dy, g, v, z);
  for (int y = 0; y < h; ++y)
    squared_distance_1d(&d[static_cast<std::size_t>(y) * w], w, 1, dx, g, v, z);
  std::vector<double> out(static_cast<std::size_t>(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      out[static_cast<std::size_t>(y) * width + x] =
          std::sqrt(d[static_cast<std::size_t>(y + pad) * w + x + pad]);
  return out;
}

}  // namespace drift::marks
