// Image comparison: RMSE, relative MSE and SSIM, with per-pixel errors and the
// pass/fail rule described in image_compare.h. Sums run sequentially in double
// precision, so the figures are the same bits on every run.
#include "render/image_compare.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>

#include "render/tonemap.h"
#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::render {

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s;
}

std::vector<std::string> choose_channels(const Image& a, const Image& b,
                                         const std::vector<std::string>& requested) {
  std::vector<std::string> channels = requested;
  if (channels.empty()) {
    const bool rgb = a.channel_index("R") >= 0 && a.channel_index("G") >= 0 &&
                     a.channel_index("B") >= 0 && b.channel_index("R") >= 0 &&
                     b.channel_index("G") >= 0 && b.channel_index("B") >= 0;
    channels = rgb ? std::vector<std::string>{"R", "G", "B"} : a.channels;
  }
  for (const auto& c : channels) {
    if (a.channel_index(c) < 0 || b.channel_index(c) < 0) {
      throw Error("channel '" + c + "' is not in both images (first has " + join(a.channels) +
                  ", second has " + join(b.channels) + "); choose channels with --channels");
    }
  }
  return channels;
}

// Luminance -> 8-bit-equivalent display value, the domain SSIM's constants are
// defined for (Wang et al. 2004 use L = 255).
std::vector<float> luma8(const Image& im, const std::vector<int>& idx) {
  const std::size_t n = static_cast<std::size_t>(im.width) * im.height;
  std::vector<float> out(n);
  const bool rgb = idx.size() >= 3;
  for (std::size_t p = 0; p < n; ++p) {
    const float* s = &im.pixels[p * im.channels.size()];
    // Rec. 709 / sRGB luminance weights.
    const float y =
        rgb ? 0.2126f * s[idx[0]] + 0.7152f * s[idx[1]] + 0.0722f * s[idx[2]] : s[idx[0]];
    out[p] = 255.0f * srgb_encode(y);
  }
  return out;
}

// Gaussian-weighted local mean with an 11x11 window, sigma 1.5 (Wang et al.
// 2004, section III-C), applied separably; at the borders the weights that fall
// inside the image are renormalised to sum to 1.
std::vector<double> gaussian_mean(const std::vector<double>& v, int w, int h) {
  constexpr int taps = 11;
  constexpr int radius = taps / 2;
  std::array<double, taps> k{};
  for (int i = -radius; i <= radius; ++i) k[i + radius] = std::exp(-(i * i) / (2.0 * 1.5 * 1.5));
  std::vector<double> tmp(v.size()), out(v.size());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double s = 0, ws = 0;
      for (int i = std::max(-radius, -x); i <= std::min(radius, w - 1 - x); ++i) {
        s += k[i + radius] * v[static_cast<std::size_t>(y) * w + x + i];
        ws += k[i + radius];
      }
      tmp[static_cast<std::size_t>(y) * w + x] = s / ws;
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double s = 0, ws = 0;
      for (int i = std::max(-radius, -y); i <= std::min(radius, h - 1 - y); ++i) {
        s += k[i + radius] * tmp[static_cast<std::size_t>(y + i) * w + x];
        ws += k[i + radius];
      }
      out[static_cast<std::size_t>(y) * w + x] = s / ws;
    }
  }
  return out;
}

// Each metric with its name: metric_name and parse_metric read the one list.
struct NamedMetric {
  CompareMetric metric;
  const char* name;
};
constexpr NamedMetric kMetrics[] = {{CompareMetric::Rmse, "rmse"},
                                    {CompareMetric::RelMse, "relmse"},
                                    {CompareMetric::Ssim, "ssim"}};

}  // namespace

const char* metric_name(CompareMetric metric) {
  for (const NamedMetric& m : kMetrics)
    if (m.metric == metric) return m.name;
  return "?";
}

CompareMetric parse_metric(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const NamedMetric& m : kMetrics)
    if (n == m.name) return m.metric;
  throw Error("unknown metric '" + name + "'; use rmse, relmse or ssim");
}

double ssim_index(const std::vector<float>& x, const std::vector<float>& y, int w, int h,
                  std::vector<float>* map) {
  const std::size_t n = static_cast<std::size_t>(w) * h;
  std::vector<double> xd(x.begin(), x.end()), yd(y.begin(), y.end()), xx(n), yy(n), xy(n);
  for (std::size_t i = 0; i < n; ++i) {
    xx[i] = xd[i] * xd[i];
    yy[i] = yd[i] * yd[i];
    xy[i] = xd[i] * yd[i];
  }
  const auto mx = gaussian_mean(xd, w, h), my = gaussian_mean(yd, w, h);
  const auto sxx = gaussian_mean(xx, w, h), syy = gaussian_mean(yy, w, h),
             sxy = gaussian_mean(xy, w, h);
  // Wang et al. 2004, eq. 7 with K1 = 0.01, K2 = 0.03, L = 255.
  constexpr double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
  if (map) map->assign(n, 0.0f);
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double vx = sxx[i] - mx[i] * mx[i], vy = syy[i] - my[i] * my[i],
                 cxy = sxy[i] - mx[i] * my[i];
    const double s = ((2 * mx[i] * my[i] + c1) * (2 * cxy + c2)) /
                     ((mx[i] * mx[i] + my[i] * my[i] + c1) * (vx + vy + c2));
    if (map) (*map)[i] = static_cast<float>(s);
    sum += s;
  }
  return sum / static_cast<double>(n);  // eq. 13: mean SSIM
}

namespace {

void check_comparison(const Image& a, const Image& b, const ComparisonOptions& o) {
  if (a.width != b.width || a.height != b.height) {
    throw Error("image sizes differ: " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                " vs " + std::to_string(b.width) + "x" + std::to_string(b.height) +
                "; compare images rendered at the same size");
  }
  if (!(o.threshold >= 0) || !std::isfinite(o.threshold)) {
    throw Error("threshold " + std::to_string(o.threshold) + " must be a finite number >= 0");
  }
  if (!(o.fail_percent >= 0 && o.fail_percent <= 100)) {
    throw Error("fail percent " + std::to_string(o.fail_percent) + " must be in [0, 100]");
  }
  if (!(o.relmse_epsilon > 0)) throw Error("relMSE epsilon must be > 0");
}

// RMSE and relMSE over the compared channels (ia of a, ib of b), whole and per pixel.
void squared_errors(const Image& a, const Image& b, const std::vector<int>& ia,
                    const std::vector<int>& ib, double epsilon, ComparisonResult& r,
                    std::vector<float>& pix_rmse, std::vector<float>& pix_rel) {
  const std::size_t n = static_cast<std::size_t>(a.width) * a.height;
  const std::size_t nc = ia.size();
  pix_rmse.assign(n, 0.0f);
  pix_rel.assign(n, 0.0f);
  double se = 0, rel = 0;
  for (std::size_t p = 0; p < n; ++p) {
    const float* pa = &a.pixels[p * a.channels.size()];
    const float* pb = &b.pixels[p * b.channels.size()];
    double pse = 0, prel = 0;
    for (std::size_t c = 0; c < nc; ++c) {
      const double d = static_cast<double>(pa[ia[c]]) - pb[ib[c]];
      const double ref = pb[ib[c]];
      pse += d * d;
      prel += d * d / (ref * ref + epsilon);
    }
    se += pse;
    rel += prel;
    pix_rmse[p] = static_cast<float>(std::sqrt(pse / nc));
    pix_rel[p] = static_cast<float>(prel / nc);
  }
  const double count = static_cast<double>(n * nc);
  r.rmse = std::sqrt(se / count);
  r.relmse = rel / count;
}

// The per-pixel error of the chosen metric, the share of pixels over the
// per-pixel threshold and the verdict.
void judge(const ComparisonOptions& o, const std::vector<float>& pix_rmse,
           const std::vector<float>& pix_rel, const std::vector<float>& ssim_map,
           ComparisonResult& r) {
  const std::size_t n = pix_rmse.size();
  for (std::size_t p = 0; p < n; ++p) {
    switch (o.metric) {
      case CompareMetric::Rmse:
        r.pixel_error.pixels[p] = pix_rmse[p];
        break;
      case CompareMetric::RelMse:
        r.pixel_error.pixels[p] = pix_rel[p];
        break;
      case CompareMetric::Ssim:
        r.pixel_error.pixels[p] = std::max(0.0f, 1.0f - ssim_map[p]);
        break;
    }
  }
  r.error = o.metric == CompareMetric::Rmse     ? r.rmse
            : o.metric == CompareMetric::RelMse ? r.relmse
                                                : 1.0 - r.ssim;
  r.pixel_threshold = o.pixel_threshold >= 0 ? o.pixel_threshold : o.threshold;
  std::size_t over = 0;
  for (float e : r.pixel_error.pixels) {
    if (e > r.pixel_threshold) ++over;
    r.max_pixel_error = std::max(r.max_pixel_error, static_cast<double>(e));
  }
  r.percent_over = 100.0 * static_cast<double>(over) / static_cast<double>(n);
  r.passed = r.error <= o.threshold && r.percent_over <= o.fail_percent;
}

}  // namespace

ComparisonResult compare_images(const Image& a, const Image& b, const ComparisonOptions& o) {
  check_comparison(a, b, o);
  // The two images and, at the peak (SSIM's means), per pixel: two luma
  // planes and two per-pixel errors (4 B each), five double planes and their
  // five Gaussian means (8 B each) and one blur's two work planes; counted with
  // the images, as the run's estimate (MemoryEstimate.ImagesOfRenderCompareAndSheet).
  const std::uint64_t pixels = static_cast<std::uint64_t>(a.width) * a.height;
  require_memory(
      (a.pixels.size() + b.pixels.size()) * sizeof(float) +
          pixels * (4 * sizeof(float) + 12 * sizeof(double)),
      "comparing two " + std::to_string(a.width) + " x " + std::to_string(a.height) + " images",
      "compare a --region of them");
  ComparisonResult r;
  r.channels = choose_channels(a, b, o.channels);
  std::vector<int> ia, ib;
  for (const auto& c : r.channels) {
    ia.push_back(a.channel_index(c));
    ib.push_back(b.channel_index(c));
  }
  std::vector<float> pix_rmse, pix_rel, ssim_map;
  squared_errors(a, b, ia, ib, o.relmse_epsilon, r, pix_rmse, pix_rel);
  r.ssim = ssim_index(luma8(a, ia), luma8(b, ib), a.width, a.height, &ssim_map);
  if (!std::isfinite(r.rmse) || !std::isfinite(r.relmse) || !std::isfinite(r.ssim)) {
    throw Error("the images hold NaN or infinite values in the compared channels (" +
                join(r.channels) + "); they cannot be compared");
  }
  r.pixel_error = Image(a.width, a.height, {"error"});
  judge(o, pix_rmse, pix_rel, ssim_map, r);
  return r;
}

Image difference_image(const ComparisonResult& result) {
  const Image& e = result.pixel_error;
  Image out(e.width, e.height, {"R", "G", "B"});
  // Display-referred ramp stops (sRGB 0..1) at t = 0, 0.25, 0.5, 0.75, 1.
  static constexpr float stops[5][3] = {
      {0.0f, 0.0f, 0.0f}, {0.1f, 0.2f, 0.8f}, {0.8f, 0.2f, 0.7f}, {1.0f, 0.6f, 0.1f}, {1, 1, 1}};
  const double scale = result.pixel_threshold > 0   ? 0.5 / result.pixel_threshold
                       : result.max_pixel_error > 0 ? 1.0 / result.max_pixel_error
                                                    : 0.0;
  for (std::size_t p = 0; p < e.pixels.size(); ++p) {
    const double t = std::clamp(e.pixels[p] * scale, 0.0, 1.0) * 4.0;
    const int i = std::min(3, static_cast<int>(t));
    const float f = static_cast<float>(t - i);
    for (int c = 0; c < 3; ++c) {
      out.pixels[p * 3 + c] = srgb_decode(stops[i][c] + f * (stops[i + 1][c] - stops[i][c]));
    }
  }
  return out;
}

}  // namespace drift::render
