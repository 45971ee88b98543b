#include "render/tonemap.h"

#include <gtest/gtest.h>

#include <cmath>

namespace drift::render {
namespace {

TEST(Srgb, EncodeDecodeAreInverse) {
  for (int i = 0; i <= 1000; ++i) {
    const float v = i / 1000.0f;
    EXPECT_NEAR(srgb_decode(srgb_encode(v)), v, 1e-6f) << "v = " << v;
    EXPECT_NEAR(srgb_encode(srgb_decode(v)), v, 1e-6f) << "v = " << v;
  }
}

TEST(Srgb, KnownValuesOfIec61966) {
  EXPECT_FLOAT_EQ(srgb_encode(0.0f), 0.0f);
  EXPECT_FLOAT_EQ(srgb_encode(1.0f), 1.0f);
  EXPECT_NEAR(srgb_encode(0.0031308f), 0.04045f, 1e-6f);  // the two pieces meet
  EXPECT_NEAR(srgb_encode(0.18f), 0.46135f, 1e-4f);       // middle grey
  EXPECT_NEAR(srgb_decode(0.5f), 0.21404f, 1e-4f);
  EXPECT_FLOAT_EQ(srgb_encode(-1.0f), 0.0f);
  EXPECT_FLOAT_EQ(srgb_encode(2.0f), 1.0f);
}

TEST(ToneCurve, FilmicIsMonotoneBoundedAndZeroAtZero) {
  const DisplayTransform filmic{};
  EXPECT_EQ(apply_tone_curve(0.0f, filmic), 0.0f);
  float previous = 0.0f;
  for (int i = 1; i <= 100000; ++i) {
    const float x = 1e-4f * i * i * 1e-2f;  // 0 .. 1e4, dense near 0
    const float y = apply_tone_curve(x, filmic);
    ASSERT_GE(y, previous) << "x = " << x;
    ASSERT_LE(y, 1.0f);
    previous = y;
  }
  EXPECT_GT(apply_tone_curve(1e4f, filmic), 0.999f);  // saturates towards 1
  EXPECT_LT(apply_tone_curve(0.5f, filmic), 0.7f);    // shoulder compresses
  EXPECT_EQ(apply_tone_curve(INFINITY, filmic), 1.0f);
  EXPECT_EQ(apply_tone_curve(NAN, filmic), 0.0f);
  EXPECT_EQ(apply_tone_curve(-3.0f, filmic), 0.0f);
}

TEST(ToneCurve, ClampAndExposure) {
  const DisplayTransform clamp{0.0, ToneCurve::Clamp};
  EXPECT_FLOAT_EQ(apply_tone_curve(0.25f, clamp), 0.25f);
  EXPECT_FLOAT_EQ(apply_tone_curve(7.0f, clamp), 1.0f);
  const DisplayTransform plus_one{1.0, ToneCurve::Clamp};
  EXPECT_FLOAT_EQ(apply_tone_curve(0.25f, plus_one), 0.5f);  // +1 EV doubles
  const DisplayTransform minus_two{-2.0, ToneCurve::Clamp};
  EXPECT_FLOAT_EQ(apply_tone_curve(0.8f, minus_two), 0.2f);
}

}  // namespace
}  // namespace drift::render
