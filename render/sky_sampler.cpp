#include "render/sky_sampler.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "render/color.h"
#include "render/fast_math.h"

namespace drift::render {

namespace {
constexpr float kPi = std::numbers::pi_v<float>;
}  // namespace

Distribution1D::Distribution1D(std::vector<float> f) : f_(std::move(f)), cdf_(f_.size() + 1) {
  const int n = size();
  // PBRT 3, 13.3.1: the running integral, normalised (uniform if all zero).
  cdf_[0] = 0.0f;
  for (int i = 0; i < n; ++i) cdf_[i + 1] = cdf_[i] + f_[i] / static_cast<float>(n);
  integral_ = cdf_[n];
  for (int i = 1; i <= n; ++i)
    cdf_[i] = integral_ > 0.0f ? cdf_[i] / integral_ : static_cast<float>(i) / n;
  guide_.resize(n + 1);
  for (int g = 0; g <= n; ++g) {
    const float level = static_cast<float>(g) / static_cast<float>(n);
    guide_[g] = static_cast<int>(std::upper_bound(cdf_.begin(), cdf_.end(), level) - cdf_.begin());
  }
}

float Distribution1D::sample(float u, float& pdf, int& cell) const {
  // The last cdf entry <= u (ties: the first cell with a nonzero width).
  // The answer lies between the guides of the cells either side of u's
  // (one cell of slack each way for the rounding of u x size); u outside
  // [0, 1) searches the whole table.
  const int n = size();
  auto lo = cdf_.begin(), hi = cdf_.end();
  if (u >= 0.0f && u < 1.0f) {
    const int g = static_cast<int>(u * static_cast<float>(n));
    lo = cdf_.begin() + guide_[std::max(g - 1, 0)];
    hi = cdf_.begin() + std::min(guide_[std::min(g + 2, n)] + 1, n + 1);
  }
  const auto it = std::upper_bound(lo, hi, u);
  cell = std::clamp(static_cast<int>(it - cdf_.begin()) - 1, 0, n - 1);
  float du = u - cdf_[cell];
  const float width = cdf_[cell + 1] - cdf_[cell];
  if (width > 0.0f) du /= width;
  pdf = this->pdf(cell);
  return std::min((static_cast<float>(cell) + du) / static_cast<float>(size()), 0.99999994f);
}

SkySampler::SkySampler(const std::function<Eigen::Vector3f(const Eigen::Vector3f&)>& radiance,
                       int rows, int columns)
    : rows_(rows), columns_(columns), marginal_({0.0f}) {
  std::vector<float> row_integrals(rows);
  conditional_.reserve(rows);
  for (int r = 0; r < rows; ++r) {
    const float theta = kPi * (static_cast<float>(r) + 0.5f) / static_cast<float>(rows);
    const float sin_t = std::sin(theta), cos_t = std::cos(theta);
    std::vector<float> f(columns);
    for (int c = 0; c < columns; ++c) {
      const float phi = 2.0f * kPi * (static_cast<float>(c) + 0.5f) / static_cast<float>(columns);
      const Eigen::Vector3f d(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t);
      // Luminance (Rec. 709) times the cell's solid-angle factor sin(theta).
      f[c] = std::max(0.0f, luminance(radiance(d))) * sin_t;
    }
    conditional_.emplace_back(std::move(f));
    row_integrals[r] = conditional_.back().integral();
  }
  marginal_ = Distribution1D(std::move(row_integrals));
}

bool SkySampler::sample(float u1, float u2, Sample& s) const {
  if (!(marginal_.integral() > 0.0f)) return false;
  float pdf_v, pdf_u;
  int row, column;
  const float v = marginal_.sample(u2, pdf_v, row);
  const float u = conditional_[row].sample(u1, pdf_u, column);
  const float theta = v * kPi, phi = u * 2.0f * kPi;
  const float sin_t = std::sin(theta);
  if (!(sin_t > 0.0f) || !(pdf_u * pdf_v > 0.0f)) return false;
  s.dir = Eigen::Vector3f(sin_t * std::cos(phi), sin_t * std::sin(phi), std::cos(theta));
  // (u, v) -> direction: dw = 2 pi^2 sin(theta) du dv (PBRT 3, eq. 14.9).
  s.pdf = pdf_u * pdf_v / (2.0f * kPi * kPi * sin_t);
  return true;
}

float SkySampler::pdf(const Eigen::Vector3f& dir) const {
  const float z = std::clamp(dir.z(), -1.0f, 1.0f);
  const float theta = fast_acos(z);
  float phi = fast_atan2(dir.y(), dir.x());
  if (phi < 0.0f) phi += 2.0f * kPi;
  const float sin_t = std::sqrt((1.0f - z) * (1.0f + z));  // sin(acos z), no third call
  if (!(sin_t > 0.0f)) return 0.0f;
  const int row =
      std::clamp(static_cast<int>(theta / kPi * static_cast<float>(rows_)), 0, rows_ - 1);
  const int column = std::clamp(static_cast<int>(phi / (2.0f * kPi) * static_cast<float>(columns_)),
                                0, columns_ - 1);
  return conditional_[row].pdf(column) * marginal_.pdf(row) / (2.0f * kPi * kPi * sin_t);
}

}  // namespace drift::render
