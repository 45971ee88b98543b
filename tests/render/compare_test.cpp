#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "render/image.h"
#include "render/image_compare.h"
#include "terrain/error.h"

namespace drift::render {
namespace {

// A smooth test picture with structure at several scales, values in [0.05, 0.95].
Image picture(int w, int h) {
  Image im(w, h, {"R", "G", "B"});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        im.at(x, y, c) = 0.5f + 0.45f * std::sin(0.13f * x * (c + 1) + 0.07f * y) *
                                    std::cos(0.05f * y + 0.3f * c);
  return im;
}

TEST(Compare, IdenticalImagesHaveZeroErrorAndSsimOne) {
  const Image a = picture(64, 48);
  const ComparisonResult r = compare_images(a, a, {});
  EXPECT_EQ(r.rmse, 0.0);
  EXPECT_EQ(r.relmse, 0.0);
  EXPECT_NEAR(r.ssim, 1.0, 1e-12);
  EXPECT_TRUE(r.passed);
  EXPECT_EQ(r.percent_over, 0.0);
}

TEST(Compare, ConstantOffsetGivesRmseEqualToOffsetAndAnalyticRelMse) {
  const Image b(40, 30, {"R", "G", "B"}, 0.5f);
  Image a = b;
  for (float& v : a.pixels) v += 0.125f;
  ComparisonOptions o;
  o.metric = CompareMetric::Rmse;
  const ComparisonResult r = compare_images(a, b, o);
  EXPECT_NEAR(r.rmse, 0.125, 1e-7) << "rmse " << r.rmse << " vs offset 0.125";
  // relMSE = d^2 / (b^2 + eps) = 0.015625 / (0.25 + 0.01)
  EXPECT_NEAR(r.relmse, 0.015625 / 0.26, 1e-7);
  EXPECT_FALSE(r.passed);  // 0.125 > default threshold 0.01
}

TEST(Compare, SsimDropsWithNoise) {
  const Image b = picture(80, 60);
  double previous = 1.0;
  for (float sigma : {0.01f, 0.05f, 0.2f}) {
    Image a = b;
    std::mt19937 rng(7);
    std::normal_distribution<float> n(0.0f, sigma);
    for (float& v : a.pixels) v += n(rng);
    const ComparisonResult r = compare_images(a, b, {});
    EXPECT_LT(r.ssim, previous) << "sigma " << sigma;
    previous = r.ssim;
  }
  EXPECT_LT(previous, 0.8);
}

TEST(Compare, SsimOfConstantImagesMatchesTheLuminanceTerm) {
  // Constant images have zero variance, so SSIM reduces to Wang et al. 2004
  // eq. 6: (2 mx my + C1) / (mx^2 + my^2 + C1), with C1 = (0.01 * 255)^2.
  const int w = 23, h = 17;
  const std::vector<float> x(w * h, 100.0f), y(w * h, 140.0f);
  const double c1 = (0.01 * 255) * (0.01 * 255);
  const double expected = (2 * 100.0 * 140.0 + c1) / (100.0 * 100.0 + 140.0 * 140.0 + c1);
  std::vector<float> map;
  const double s = ssim_index(x, y, w, h, &map);
  EXPECT_NEAR(s, expected, 1e-9) << "ssim " << s << " vs closed form " << expected;
  EXPECT_NEAR(map[0], expected, 1e-6);  // also at the border (renormalised window)
}

TEST(Compare, SsimIsSymmetricAndSeesContrastLoss) {
  // SSIM is symmetric in its two images (eq. 7), and halving the contrast
  // lowers its contrast term.
  const Image a = picture(40, 30);
  Image b = a;
  for (float& v : b.pixels) v = 0.5f + 0.5f * (v - 0.5f);
  const ComparisonResult ab = compare_images(a, b, {}), ba = compare_images(b, a, {});
  EXPECT_NEAR(ab.ssim, ba.ssim, 1e-12);
  EXPECT_LT(ab.ssim, 0.99);
}

TEST(Compare, ThresholdAndFailPercentLogic) {
  const Image b(10, 10, {"R", "G", "B"}, 0.5f);
  Image a = b;
  // 5 of 100 pixels off by 0.5 in every channel: rmse = sqrt(5 * 0.25 / 100).
  for (int i = 0; i < 5; ++i)
    for (int c = 0; c < 3; ++c) a.at(i, 0, c) = 1.0f;
  ComparisonOptions o;
  o.metric = CompareMetric::Rmse;
  o.threshold = 0.2;
  ComparisonResult r = compare_images(a, b, o);
  EXPECT_NEAR(r.rmse, std::sqrt(0.0125), 1e-7);
  EXPECT_NEAR(r.percent_over, 5.0, 1e-9);
  EXPECT_TRUE(r.passed);  // fail_percent defaults to 100
  o.fail_percent = 4.0;
  EXPECT_FALSE(compare_images(a, b, o).passed);  // 5% > 4%
  o.fail_percent = 5.0;
  EXPECT_TRUE(compare_images(a, b, o).passed);  // 5% <= 5%
  o.threshold = 0.1;
  EXPECT_FALSE(compare_images(a, b, o).passed);  // rmse 0.112 > 0.1
  o.pixel_threshold = 0.6;                       // per-pixel error 0.5 now within tolerance
  o.threshold = 0.2;
  o.fail_percent = 0.0;
  r = compare_images(a, b, o);
  EXPECT_EQ(r.percent_over, 0.0);
  EXPECT_TRUE(r.passed);
}

TEST(Compare, SizeMismatchAndMissingChannelsAreErrors) {
  const Image a(10, 10, {"R", "G", "B"}), b(10, 11, {"R", "G", "B"});
  try {
    compare_images(a, b, {});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("10x10 vs 10x11"), std::string::npos) << e.what();
  }
  ComparisonOptions o;
  o.channels = {"depth"};
  EXPECT_THROW(compare_images(a, a, o), Error);
  EXPECT_THROW(parse_metric("psnr"), Error);
}

TEST(Compare, DifferenceImageMarksTheChangedPixels) {
  const Image b(16, 16, {"R", "G", "B"}, 0.5f);
  Image a = b;
  for (int c = 0; c < 3; ++c) a.at(8, 8, c) = 0.9f;
  ComparisonOptions o;
  o.metric = CompareMetric::Rmse;
  const Image d = difference_image(compare_images(a, b, o));
  EXPECT_EQ(d.at(0, 0, 0) + d.at(0, 0, 1) + d.at(0, 0, 2), 0.0f);
  EXPECT_GT(d.at(8, 8, 0), 0.5f);  // over the tolerance: the warm end of the ramp
}

TEST(Compare, CropKeepsTheRectangleAndRefusesOneOutside) {
  Image img(4, 3, {"R", "G"});
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) {
      img.at(x, y, 0) = static_cast<float>(10 * y + x);
      img.at(x, y, 1) = -static_cast<float>(10 * y + x);
    }
  const Image c = crop(img, 1, 1, 2, 2);
  ASSERT_EQ(c.width, 2);
  ASSERT_EQ(c.height, 2);
  EXPECT_EQ(c.channels, img.channels);
  EXPECT_EQ(c.at(0, 0, 0), 11.0f);
  EXPECT_EQ(c.at(1, 0, 0), 12.0f);
  EXPECT_EQ(c.at(0, 1, 0), 21.0f);
  EXPECT_EQ(c.at(1, 1, 1), -22.0f);
  EXPECT_THROW(crop(img, 3, 0, 2, 1), Error);
  EXPECT_THROW(crop(img, 0, 0, 0, 1), Error);
  EXPECT_THROW(crop(img, -1, 0, 1, 1), Error);
  // x + w and y + h beyond an int (a hostile --region) must not wrap past the check.
  const int huge = std::numeric_limits<int>::max();
  EXPECT_THROW(crop(img, huge - 1, 0, 2, 1), Error);
  EXPECT_THROW(crop(img, 1, 0, huge, 1), Error);
  EXPECT_THROW(crop(img, 0, huge, 1, huge), Error);
}

}  // namespace
}  // namespace drift::render
