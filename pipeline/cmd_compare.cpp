// drift compare A B: does image A match reference B? Prints every metric, the
// chosen one against its threshold and the share of pixels over the per-pixel
// tolerance; writes a false-colour difference map on request. Exit status:
// 0 pass, 1 fail (or error), 2 usage. Semantics: render/image_compare.h.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "pipeline/cli.h"
#include "render/image_compare.h"
#include "render/image_io.h"
#include "terrain/output_set.h"

namespace drift::pipeline {

namespace {

struct CompareCommandOptions {
  std::string a, b, diff, metric = "relmse", channels;
  std::vector<int> region;  // X,Y,W,H; CLI11 refuses what an int cannot hold
  double threshold = 1e-2;
  double pixel_threshold = -1.0;
  double fail_percent = 100.0;
};

void run_compare(const CompareCommandOptions& o) {
  render::ComparisonOptions options;
  options.metric = render::parse_metric(o.metric);
  options.threshold = o.threshold;
  options.pixel_threshold = o.pixel_threshold;
  options.fail_percent = o.fail_percent;
  if (!o.channels.empty()) {
    std::string rest = o.channels;
    for (std::size_t pos; (pos = rest.find(',')) != std::string::npos; rest.erase(0, pos + 1)) {
      options.channels.push_back(rest.substr(0, pos));
    }
    options.channels.push_back(rest);
    for (const auto& c : options.channels) {
      if (c.empty()) usage_error("--channels '" + o.channels + "' has an empty channel name");
    }
  }
  OutputSet outputs({o.diff}, {o.a, o.b});
  render::Image a = render::read_image(o.a);
  render::Image b = render::read_image(o.b);
  if (!o.region.empty()) {
    const auto& r = o.region;
    a = render::crop(a, r[0], r[1], r[2], r[3]);
    b = render::crop(b, r[0], r[1], r[2], r[3]);
  }
  const render::ComparisonResult r = render::compare_images(a, b, options);
  if (!o.diff.empty()) {
    render::write_image(render::difference_image(r), o.diff,
                        render::DisplayTransform{0.0, render::ToneCurve::Clamp});
  }
  outputs.commit();
  std::string channels;
  for (const auto& c : r.channels) channels += (channels.empty() ? "" : ",") + c;
  std::printf("compare:   %s against reference %s (%dx%d, channels %s)\n", o.a.c_str(), o.b.c_str(),
              a.width, a.height, channels.c_str());
  std::printf("rmse:      %.6g\n", r.rmse);
  std::printf("relmse:    %.6g\n", r.relmse);
  std::printf("ssim:      %.6f (dssim = 1 - ssim = %.6g)\n", r.ssim, 1.0 - r.ssim);
  std::printf("metric:    %s error %.6g, threshold %.6g -> %s\n",
              render::metric_name(options.metric), r.error, options.threshold,
              r.error <= options.threshold ? "within" : "OVER");
  std::printf("pixels:    %.4f%% over per-pixel tolerance %.6g (allowed %.4g%%, max %.6g) -> %s\n",
              r.percent_over, r.pixel_threshold, options.fail_percent, r.max_pixel_error,
              r.percent_over <= options.fail_percent ? "within" : "OVER");
  if (!o.diff.empty()) std::printf("diff:      %s\n", o.diff.c_str());
  std::printf("result:    %s\n", r.passed ? "PASS" : "FAIL");
  std::fflush(stdout);
  if (!r.passed) std::exit(1);  // a failed comparison is not an error: no "drift: error:"
}

}  // namespace

void compare_flags(CLI::App* sub, CompareCommandOptions* o) {
  sub->add_option("image", o->a, "image to test (EXR or PNG)")->required();
  sub->add_option("reference", o->b, "reference image (EXR or PNG), same size")->required();
  sub->add_option("--metric", o->metric, "rmse | relmse | ssim (error of ssim is 1 - SSIM)")
      ->check(CLI::IsMember({"rmse", "relmse", "ssim"}, CLI::ignore_case))
      ->capture_default_str();
  sub->add_option("--threshold", o->threshold, "largest error of the metric that passes, >= 0")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_option("--pixel-threshold", o->pixel_threshold,
                  "per-pixel tolerance for --fail-percent (default: --threshold)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--fail-percent", o->fail_percent,
                  "largest % of pixels allowed over the per-pixel tolerance, 0..100")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  sub->add_option("--diff", o->diff, "write a false-colour per-pixel error map (.png or .exr)");
  sub->add_option("--channels", o->channels,
                  "comma-separated channels to compare (default R,G,B, else all)");
  sub->add_option("--region", o->region,
                  "compare only the rectangle X,Y,W,H (pixels from the top left) of both images")
      ->expected(4)
      ->delimiter(',');
}

DRIFT_COMMAND(90, "compare", "compare an image with a reference (exit 0 pass, 1 fail)",
              compare_flags, run_compare);

}  // namespace drift::pipeline
