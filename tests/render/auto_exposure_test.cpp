#include "render/auto_exposure.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "render/image_io.h"
#include "terrain/error.h"

namespace drift::render {
namespace {

constexpr std::array<float, 3> kNoBalance{1.0f, 1.0f, 1.0f};

// A frame of the render's channels: radiance, albedo and the sky mask.
Image frame(int w, int h) {
  return Image(w, h, {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "mask.sky"});
}

void put(Image& im, int x, int y, float radiance, float albedo, float sky = 0.0f) {
  for (int c = 0; c < 3; ++c) im.at(x, y, c) = radiance, im.at(x, y, 3 + c) = albedo;
  im.at(x, y, 6) = sky;
}

TEST(AutoExposure, GreyCardMapsToMiddleGrey) {
  // A uniform grey card (albedo 0.18) seen at radiance 0.037: whichever way
  // it is metered, it comes out at 0.18 before the tone curve.
  for (const float radiance : {0.037f, 1.0f, 55.0f}) {
    Image card = frame(16, 9);
    for (int y = 0; y < 9; ++y)
      for (int x = 0; x < 16; ++x) put(card, x, y, radiance, 0.18f);
    const Metering incident = meter_exposure(card, kNoBalance);
    EXPECT_TRUE(incident.incident);
    EXPECT_NEAR(radiance * std::exp2(incident.exposure_ev), 0.18, 1e-5) << radiance;
    Image plain(16, 9, {"R", "G", "B"}, radiance);
    const Metering reflected = meter_exposure(plain, kNoBalance);
    EXPECT_FALSE(reflected.incident);
    EXPECT_NEAR(radiance * std::exp2(reflected.exposure_ev), 0.18, 1e-5) << radiance;
  }
}

TEST(AutoExposure, SnowStaysWhiteAndRockDark) {
  // Snow (0.9) and dark rock (0.12) in the same light E = 2: the incident
  // meter keeps their reflectances; a reflected meter would pull them to grey.
  Image scene = frame(20, 10);
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 20; ++x) {
      const float albedo = (x + y) % 4 == 0 ? 0.12f : 0.9f;  // mostly snow
      put(scene, x, y, 2.0f * albedo, albedo);
    }
  const double k = std::exp2(meter_exposure(scene, kNoBalance).exposure_ev);
  EXPECT_NEAR(2.0 * 0.9 * k, 0.9, 1e-5);
  EXPECT_NEAR(2.0 * 0.12 * k, 0.12, 1e-5);
}

TEST(AutoExposure, SkyDoesNotMoveTheIncidentMeter) {
  Image scene = frame(16, 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) put(scene, x, y, 0.5f * 0.3f, 0.3f);
  const double ground_only = meter_exposure(scene, kNoBalance).exposure_ev;
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 16; ++x) put(scene, x, y, 8.0f, 0.0f, 1.0f);  // a bright sky
  EXPECT_NEAR(meter_exposure(scene, kNoBalance).exposure_ev, ground_only, 1e-9);
}

TEST(AutoExposure, CentreWeighted) {
  // The centre lit at 4, a wider rim at 1: the centre's light wins the median.
  Image scene = frame(40, 40);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) {
      const bool centre = std::abs(x - 19.5) < 11 && std::abs(y - 19.5) < 11;
      put(scene, x, y, (centre ? 4.0f : 1.0f) * 0.2f, 0.2f);
    }
  EXPECT_NEAR(meter_exposure(scene, kNoBalance).exposure_ev, -2.0, 1e-6);
}

TEST(AutoExposure, FarGroundsAirDoesNotMoveTheMeter) {
  // Near ground (depth 2 km, albedo 0.2) in light 1; the far half of the
  // frame (20 km) dark forest (0.04) whose radiance is mostly the air's own
  // light: radiance over albedo reads 4x the light there. The meter reads
  // the nearer half: light 1, 0 EV (reading all of it gave -2 EV).
  Image scene(20, 20, {"R", "G", "B", "depth", "albedo.R", "albedo.G", "albedo.B", "mask.sky"});
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) {
      const bool far = y < 10;
      const float albedo = far ? 0.04f : 0.2f;
      const float radiance = far ? 0.04f * 0.8f + 0.13f : 0.2f;
      for (int c = 0; c < 3; ++c) scene.at(x, y, c) = radiance, scene.at(x, y, 4 + c) = albedo;
      scene.at(x, y, 3) = far ? 20000.0f : 2000.0f;
    }
  EXPECT_NEAR(meter_exposure(scene, kNoBalance).exposure_ev, 0.0, 1e-6);
}

TEST(AutoExposure, WhiteBalanceIsMetered) {
  Image plain(4, 4, {"R", "G", "B"}, 0.5f);
  const std::array<float, 3> gains{2.0f, 2.0f, 2.0f};
  EXPECT_NEAR(meter_exposure(plain, gains).exposure_ev, std::log2(0.18 / 1.0), 1e-6);
}

TEST(AutoExposure, BlackFrameAndBadImages) {
  EXPECT_EQ(meter_exposure(frame(8, 8), kNoBalance).exposure_ev, 0.0);
  EXPECT_THROW(meter_exposure(Image(2, 2, {"depth"}), kNoBalance), Error);
}

TEST(AutoExposure, PngIsWrittenMetered) {
  // The grey card through write_png: middle grey after the tone curve,
  // and the compensation (exposure_ev) added on top of the meter.
  Image card = frame(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) put(card, x, y, 3.3f, 0.18f);
  const auto path = std::filesystem::temp_directory_path() / "drift_auto_exposure.png";
  DisplayTransform display;
  display.curve = ToneCurve::Clamp;
  display.auto_exposure = true;
  write_png(card, path, display);
  EXPECT_NEAR(read_image(path).at(3, 3, 1), 0.18f, 0.003f);
  display.exposure_ev = 1.0;
  write_png(card, path, display);
  EXPECT_NEAR(read_image(path).at(3, 3, 1), 0.36f, 0.005f);
  // Through the filmic curve too: the card at 0.18 (sRGB 118), as a camera's
  // standard output shows it, not lifted to 0.267 by the curve's mid-tones.
  display.curve = ToneCurve::Filmic;
  display.exposure_ev = 0.0;
  write_png(card, path, display);
  EXPECT_NEAR(read_image(path).at(3, 3, 1), 0.18f, 0.003f);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace drift::render
