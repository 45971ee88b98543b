// Camera paths (render/camera.h, camera_at): a Catmull-Rom spline through
// the keyframes over their own times.
#include <gtest/gtest.h>

#include "render/camera.h"

using namespace drift::render;

namespace {

std::vector<CameraKey> bent_path() {
  return {{0.0, {0, 0, 100}, {0, 1000, 0}, 40.0},
          {2.0, {200, 50, 150}, {100, 1000, 0}, 30.0},
          {3.0, {300, 300, 120}, {400, 900, 50}, 35.0},
          {6.0, {250, 700, 300}, {800, 800, 0}, 50.0}};
}

}  // namespace

TEST(CameraPath, PassesThroughEveryKeyAndHoldsOutside) {
  const auto keys = bent_path();
  for (const CameraKey& k : keys) {
    const Camera c = camera_at(keys, k.time);
    EXPECT_LT((c.from - k.from).norm(), 1e-9) << k.time;
    EXPECT_LT((c.to - k.to).norm(), 1e-9) << k.time;
    EXPECT_NEAR(c.vertical_fov_deg, k.fov_deg, 1e-9);
  }
  EXPECT_EQ(camera_at(keys, -5.0).from, keys.front().from);
  EXPECT_EQ(camera_at(keys, 99.0).from, keys.back().from);
}

TEST(CameraPath, SmoothThroughTheKeys) {
  // C1: the velocity just before a key equals the velocity just after it
  // (a piecewise-linear path would jump: (200,50)/2 s -> (100,250)/1 s).
  const auto keys = bent_path();
  const double h = 1e-5;
  for (std::size_t i = 1; i + 1 < keys.size(); ++i) {
    const double t = keys[i].time;
    const Eigen::Vector3d before = (camera_at(keys, t).from - camera_at(keys, t - h).from) / h;
    const Eigen::Vector3d after = (camera_at(keys, t + h).from - camera_at(keys, t).from) / h;
    EXPECT_LT((before - after).norm(), 1e-2 * (1.0 + before.norm())) << "at key " << i;
  }
}

TEST(CameraPath, EvenKeysOnALineMoveEvenly) {
  // Catmull-Rom reproduces a straight, even motion exactly.
  std::vector<CameraKey> keys;
  for (int i = 0; i < 4; ++i)
    keys.push_back({i * 1.5, {10.0 * i, 5.0 * i, 100}, {0, 1000, 0}, 40.0});
  for (double t = 0.0; t <= 4.5; t += 0.37) {
    const Eigen::Vector3d expected(10.0 * t / 1.5, 5.0 * t / 1.5, 100);
    EXPECT_LT((camera_at(keys, t).from - expected).norm(), 1e-9) << t;
  }
}
