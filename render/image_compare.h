// Comparing two images: a rendered image against a reference, as a pass/fail
// test with figures (RMSE, relative MSE, SSIM) and a false-colour difference map.
//
// Semantics (docs/compare.md):
//   * Both images must have the same width and height; the compared channels
//     (default R, G, B if both have them, otherwise every channel of A) must
//     exist in both.
//   * RMSE   = sqrt( mean over pixels and channels of (a - b)^2 ).
//   * relMSE = mean over pixels and channels of (a - b)^2 / (b^2 + eps), b the
//              reference (the second image), eps = 1e-2 (the usual rendering
//              relative MSE, e.g. Rousselle et al. 2011).
//   * SSIM   = mean SSIM index (Wang et al. 2004, eq. 13) of the luminances
//              Y = 0.2126 R + 0.7152 G + 0.0722 B, each clamped to [0, 1],
//              sRGB-encoded and scaled to [0, 255] (8-bit equivalent);
//              Gaussian 11x11 window, sigma 1.5, weights renormalised at the
//              borders; C1 = (0.01 * 255)^2, C2 = (0.03 * 255)^2. The error
//              figure for SSIM is DSSIM = 1 - SSIM (0 = identical).
//   * Per-pixel error of the chosen metric: rmse -> RMS over the channels of
//     the pixel; relmse -> mean relative squared error over the channels;
//     ssim -> 1 - SSIM map value.
//   * Pass <=> error(metric) <= threshold AND the percentage of pixels whose
//     per-pixel error exceeds pixel_threshold is <= fail_percent
//     (as OpenImageIO's `idiff -fail T -failpercent P`).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "render/image.h"

namespace drift::render {

enum class CompareMetric { Rmse, RelMse, Ssim };

struct ComparisonOptions {
  CompareMetric metric = CompareMetric::RelMse;
  double threshold = 1e-2;            // maximum error of `metric` (DSSIM for ssim), >= 0
  double pixel_threshold = -1.0;      // per-pixel tolerance, >= 0; < 0 means "same as threshold"
  double fail_percent = 100.0;        // % of pixels allowed above pixel_threshold, [0, 100]
  std::vector<std::string> channels;  // empty: R,G,B if both have them, else all of A
  double relmse_epsilon = 1e-2;       // eps of relMSE, > 0
};

struct ComparisonResult {
  double rmse = 0.0;
  double relmse = 0.0;
  double ssim = 1.0;           // mean SSIM in [-1, 1]; 1 = identical
  double error = 0.0;          // the chosen metric's error (rmse, relmse or 1 - ssim)
  double pixel_threshold = 0;  // the per-pixel tolerance used
  double percent_over = 0.0;   // % of pixels whose per-pixel error > pixel_threshold
  double max_pixel_error = 0;  // largest per-pixel error
  bool passed = true;
  std::vector<std::string> channels;  // the channels compared
  Image pixel_error;                  // one channel "error": per-pixel error of the metric
};

const char* metric_name(CompareMetric metric);
// "rmse", "relmse" or "ssim" (case-insensitive); throws drift::Error otherwise.
CompareMetric parse_metric(const std::string& name);

// Compares `a` (test) with `b` (reference). Throws drift::Error on mismatched
// sizes, missing channels or bad options.
ComparisonResult compare_images(const Image& a, const Image& b, const ComparisonOptions& options);

// Mean SSIM of two single-channel 8-bit-equivalent images (values 0..255), and
// its map if `map` is not null. Exposed for tests.
double ssim_index(const std::vector<float>& x, const std::vector<float>& y, int width, int height,
                  std::vector<float>* map = nullptr);

// False-colour map of result.pixel_error: black (0) through blue, magenta and
// orange to white at 2x the per-pixel tolerance; pixels above the tolerance are
// the warm half. Linear R, G, B (write it with a Clamp tone curve).
Image difference_image(const ComparisonResult& result);

}  // namespace drift::render
