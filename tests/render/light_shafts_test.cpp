// Light shafts (render/light_shafts.h): the terrain's shadow on the air takes
// out exactly the sun's single scattering of the shadowed air, and nothing
// where nothing is in shadow.
#include "render/light_shafts.h"

#include <gtest/gtest.h>

#include "render/renderer.h"
#include "render/terrain_scene.h"

using namespace drift::render;
using drift::terrain::HeightField;
using Eigen::Vector3f;

namespace {

const Atmosphere& atmosphere() {
  static const Atmosphere a;
  return a;
}

// A low sun in the west, seen from 1000 m above sea level, the air reaching 20 km.
const PhysicalSky& low_sun_air() {
  static const PhysicalSky air(
      atmosphere(), 1000.0, Eigen::Vector3d(-std::cos(0.17), 0.0, std::sin(0.17)), 3.0f, 20000.0);
  return air;
}

const ShadowSlab kEverywhere{-1e9f, 1e9f};

}  // namespace

TEST(LightShafts, NoShadowTakesNothing) {
  const ShaftRay ray{{0, 0, 0}, {0, 1, 0}, 5000.0f};
  const Vector3f loss = shaft_shadow_loss(low_sun_air(), 1000.0f, ray, kEverywhere, 32, 0.5f,
                                          [](const Vector3f&) { return false; });
  EXPECT_EQ(loss, Vector3f::Zero());
}

TEST(LightShafts, FullShadowTakesTheSunsSingleScattering) {
  // A level ray in shadow all along: the loss is the closed form
  // sigma_s p T_sun (1 - exp(-sigma_t d)) / sigma_t of a homogeneous layer
  // (PhysicalSky::sun_single_scattering over the whole length); the strata
  // and the aerial-perspective table's interpolation agree to 2 %.
  const PhysicalSky& air = low_sun_air();
  const Vector3f dir(0, 1, 0);  // across the sun's direction
  const ShaftRay ray{{0, 0, 0}, dir, 5000.0f};
  const Vector3f loss = shaft_shadow_loss(air, 1000.0f, ray, kEverywhere, 256, 0.5f,
                                          [](const Vector3f&) { return true; });
  const Vector3f closed_form = air.sun_single_scattering(1000.0f, dir, 5000.0f);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(loss[c], 0.0f);
    EXPECT_NEAR(loss[c], closed_form[c], 0.02f * closed_form[c]) << "channel " << c;
  }
  // Multiple scattering, lit by the whole sky, stays: the loss is less than
  // all the in-scattered light of the ray.
  const Vector3f all = air.from_camera(dir, 5000.0f).inscatter;
  for (int c = 0; c < 3; ++c) EXPECT_LT(loss[c], all[c]) << "channel " << c;
}

TEST(LightShafts, LossGrowsWithTheShadowedLength) {
  // The far half of the ray in shadow takes out less than the whole ray
  // (and more than nothing), and only heights inside the slab count.
  const PhysicalSky& air = low_sun_air();
  const ShaftRay ray{{0, 0, 0}, {0, 1, 0}, 4000.0f};
  auto loss_g = [&](auto in_shadow, ShadowSlab slab) {
    return shaft_shadow_loss(air, 1000.0f, ray, slab, 64, 0.25f, in_shadow).y();
  };
  const float whole = loss_g([](const Vector3f&) { return true; }, kEverywhere);
  const float far_half = loss_g([](const Vector3f& p) { return p.y() > 2000.0f; }, kEverywhere);
  EXPECT_GT(far_half, 0.3f * whole);
  EXPECT_LT(far_half, 0.5f * whole);  // the far half is seen through more air
  EXPECT_EQ(loss_g([](const Vector3f&) { return true; }, ShadowSlab{10.0f, 20.0f}), 0.0f);
}

TEST(LightShafts, AWallsShadowDarkensTheAirBehindIt) {
  // A 300 m wall on the west of a flat plain, a sun 10 degrees up in the west:
  // the plain lies in the wall's shadow. Looking across the shadowed plain,
  // light shafts take the sun's in-scatter out of the air; with the wall
  // removed nothing changes.
  auto render_plain = [](bool wall, bool shafts) {
    SceneInput in;
    in.terrain = HeightField(200, 200, 0.0f, drift::terrain::local_georeference(10.0));
    if (wall)
      for (int r = 0; r < 200; ++r)
        for (int x = 0; x < 20; ++x) in.terrain(x, r) = 300.0f;
    in.sun.azimuth_deg = 270.0;
    in.sun.elevation_deg = 10.0;
    in.sky.haze = 5.0f;
    in.sky.light_shafts = shafts;
    in.surface.ground.albedo = {0.05f, 0.05f, 0.05f};
    const TerrainScene scene(in);
    Camera camera;
    camera.from = scene.origin() + Eigen::Vector3d(900, 0, 60);
    camera.to = scene.origin() + Eigen::Vector3d(-300, 0, 0);
    camera.vertical_fov_deg = 10.0;
    RenderSettings rs;
    rs.width = rs.height = 8;
    rs.samples_per_pixel = 16;
    const Image image = render_image(scene, in, camera, rs);
    double sum = 0.0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) sum += image.at(x, y, 1);
    return sum / (image.width * image.height);
  };
  const double lit = render_plain(true, false), shafted = render_plain(true, true);
  EXPECT_LT(shafted, 0.9 * lit) << "lit " << lit << ", with shafts " << shafted;
  const double open = render_plain(false, false), open_shafts = render_plain(false, true);
  EXPECT_NEAR(open_shafts, open, 0.02 * open);
}
