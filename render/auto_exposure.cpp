#include "render/auto_exposure.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "render/color.h"
#include "terrain/error.h"

namespace drift::render {

namespace {

constexpr double kMiddleGrey = 0.18;
// The upper quartile: the light of the sunlit ground, as an incident meter
// held in the sun reads it (a photographer's reading for a sunny landscape),
// not moved by shadows, glints or a few bright pixels.
constexpr double kQuantile = 0.75;
// Centre weighting: a Gaussian of this sigma in units of the half diagonal.
constexpr double kCentreSigma = 0.35;
// Albedos below this are too dark to divide by (the light would be noise).
constexpr float kMinAlbedo = 0.02f;

// The weighted quantile of (value, weight) pairs.
double weighted_quantile(std::vector<std::pair<double, double>> samples, double q) {
  std::sort(samples.begin(), samples.end());
  double total = 0.0;
  for (const auto& s : samples) total += s.second;
  double run = 0.0;
  for (const auto& s : samples) {
    run += s.second;
    if (run >= q * total) return s.first;
  }
  return samples.back().first;
}

double centre_weight(const Image& im, int x, int y) {
  const double cx = 0.5 * im.width, cy = 0.5 * im.height;
  const double half_diagonal = std::hypot(cx, cy);
  const double r = std::hypot(x + 0.5 - cx, y + 0.5 - cy) / half_diagonal;
  return std::exp(-r * r / (2.0 * kCentreSigma * kCentreSigma));
}

// Incident readings (log light, weight) with the depth of their pixel.
struct Reading {
  double log_light, weight, depth;
};

// The readings of the nearer half of the ground (all if no depth was read):
// far ground's light is inflated by the air's (auto_exposure.h).
std::vector<std::pair<double, double>> nearer_half(const std::vector<Reading>& readings,
                                                   bool has_depth) {
  std::vector<std::pair<double, double>> out;
  if (readings.empty()) return out;
  double cut = std::numeric_limits<double>::infinity();
  if (has_depth) {
    std::vector<double> depths;
    depths.reserve(readings.size());
    for (const Reading& r : readings) depths.push_back(r.depth);
    auto mid = depths.begin() + static_cast<std::ptrdiff_t>((depths.size() - 1) / 2);
    std::nth_element(depths.begin(), mid, depths.end());
    cut = *mid;
  }
  for (const Reading& r : readings)
    if (r.depth <= cut) out.emplace_back(r.log_light, r.weight);
  return out;
}

}  // namespace

Metering meter_exposure(const Image& linear, const std::array<float, 3>& white_balance) {
  const int r = linear.channel_index("R"), g = linear.channel_index("G"),
            b = linear.channel_index("B");
  if (r < 0 || g < 0 || b < 0) throw Error("cannot meter an image without R, G, B channels");
  const int ar = linear.channel_index("albedo.R"), ag = linear.channel_index("albedo.G"),
            ab = linear.channel_index("albedo.B"), sky = linear.channel_index("mask.sky"),
            depth = linear.channel_index("Z") >= 0 ? linear.channel_index("Z")
                                                   : linear.channel_index("depth");
  const bool has_aovs = ar >= 0 && ag >= 0 && ab >= 0 && sky >= 0;
  // log(light) and weight per metered pixel, incident (ground) and reflected (all).
  std::vector<std::pair<double, double>> reflected;
  std::vector<Reading> readings;
  for (int y = 0; y < linear.height; ++y) {
    for (int x = 0; x < linear.width; ++x) {
      const Eigen::Vector3f rgb(linear.at(x, y, r) * white_balance[0],
                                linear.at(x, y, g) * white_balance[1],
                                linear.at(x, y, b) * white_balance[2]);
      const float l = luminance(rgb);
      if (!(l > 0.0f) || !std::isfinite(l)) continue;
      const double w = centre_weight(linear, x, y);
      reflected.emplace_back(std::log(l / kMiddleGrey), w);
      if (!has_aovs || linear.at(x, y, sky) >= 0.5f) continue;
      const float a = luminance({linear.at(x, y, ar), linear.at(x, y, ag), linear.at(x, y, ab)});
      const float d = depth >= 0 ? linear.at(x, y, depth) : 0.0f;
      if (a >= kMinAlbedo)
        readings.push_back(
            {std::log(l / a), w, std::isnan(d) ? std::numeric_limits<double>::infinity() : d});
    }
  }
  Metering m;
  const std::size_t pixels = static_cast<std::size_t>(linear.width) * linear.height;
  m.incident = !readings.empty() && readings.size() * 100 >= pixels;
  const auto incident = nearer_half(readings, depth >= 0);
  const auto& chosen = m.incident ? incident : reflected;
  if (chosen.empty()) return m;  // black: nothing to meter
  m.light = std::exp(weighted_quantile(chosen, kQuantile));
  // 2^ev light x 0.18 = 0.18: a grey card in the metered light to middle grey.
  m.exposure_ev = std::clamp(-std::log2(m.light), -20.0, 20.0);
  return m;
}

}  // namespace drift::render
