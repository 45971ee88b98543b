// Surface layers: the bump-map pyramid (level of detail), ripple orientation,
// Oren-Nayar reflectance, and snow cover and depth as the renderer sees them.
#include "render/surface.h"

#include <gdal_priv.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <stdexcept>

#include "render/oren_nayar.h"
#include "render/renderer.h"
#include "render/terrain_scene.h"
#include "render/tonemap.h"
#include "terrain/error.h"
#include "terrain/raster_io.h"
#include "tests/render/snow_layer.h"

using namespace drift::render;
using drift::terrain::HeightField;
using drift::terrain::local_georeference;

// A footprint so wide that the ground's procedural detail is its mean
// (albedo factor 1, no relief: render/ground_detail.h), for tests of the
// material stack itself.
constexpr double kWholeDetail = 1e6;

namespace {

// The channel of Hit::coverage that snow covers.
int snow_channel(const TerrainScene& scene) {
  const auto& names = scene.coverage_names();
  const auto found = std::find(names.begin(), names.end(), "snow");
  if (found == names.end()) throw std::runtime_error("the scene has no snow channel");
  return static_cast<int>(found - names.begin());
}

constexpr double kPi = std::numbers::pi;

// A periodic tile of `n` x `n` texels of `texel` metres: crests of wavelength
// n*texel/k running north-south (height varies with u only).
HeightField sine_tile(int n, double texel, int k, double amplitude) {
  HeightField tile(n, n, 0.0f, local_georeference(texel));
  for (int row = 0; row < n; ++row)
    for (int x = 0; x < n; ++x)
      tile(x, row) = static_cast<float>(amplitude * std::sin(2 * kPi * k * x / n));
  return tile;
}

// Pseudo-random periodic tile.
HeightField noise_tile(int w, int h) {
  HeightField tile(w, h, 0.0f, local_georeference(1.0));
  std::uint32_t s = 12345;
  for (float& v : tile.values()) {
    s = s * 1664525u + 1013904223u;
    v = static_cast<float>(s >> 8) / static_cast<float>(1 << 24);
  }
  return tile;
}

// A surface with sine ripples 2 m apart laid as a normal-detail tile.
TerrainSurface rippled() {
  TerrainSurface s;
  NormalDetail ripples;
  ripples.slopes = SlopePyramid(sine_tile(64, 0.1, 2, 0.05), 0.1);
  s.normal_details = {ripples};
  return s;
}

}  // namespace

TEST(SlopePyramid, EachLevelIsTheAverageOfTheFinerOne) {
  for (auto [w, h] : {std::pair{64, 64}, std::pair{48, 20}, std::pair{7, 5}}) {
    const SlopePyramid p(noise_tile(w, h), 1.0);
    for (int i = 0; i + 1 < p.levels(); ++i) {
      // Means agree level to level (box filters keep the mean exactly).
      auto mean = [](const drift::terrain::Grid<Eigen::Vector2f>& g) {
        Eigen::Vector2d s = Eigen::Vector2d::Zero();
        for (const auto& v : g.values()) s += v.cast<double>();
        return Eigen::Vector2d(s / static_cast<double>(g.size()));
      };
      EXPECT_NEAR((mean(p.level(i)) - mean(p.level(i + 1))).norm(), 0.0, 1e-6) << w << "x" << h;
    }
    if (w % 2 == 0 && h % 2 == 0) {
      const auto& fine = p.level(0);
      const auto& coarse = p.level(1);
      for (int row = 0; row < coarse.height(); ++row)
        for (int x = 0; x < coarse.width(); ++x) {
          const Eigen::Vector2f avg =
              0.25f * (fine(2 * x, 2 * row) + fine(2 * x + 1, 2 * row) + fine(2 * x, 2 * row + 1) +
                       fine(2 * x + 1, 2 * row + 1));
          EXPECT_NEAR((coarse(x, row) - avg).norm(), 0.0f, 1e-6f);
        }
    }
    EXPECT_EQ(p.level(p.levels() - 1).size(), 1u);
  }
}

TEST(SlopePyramid, FineLevelGivesTheAnalyticSlopeAndFarAwayTheMean) {
  // h = A sin(2 pi u / L): dh/du = A 2 pi / L cos(...); central differences
  // on 64 texels per wavelength are within 0.2 %.
  const double texel = 0.05, amplitude = 0.02;
  const SlopePyramid p(sine_tile(256, texel, 4, amplitude), texel);
  const double wavelength = 256 * texel / 4;
  for (double u : {0.1, 0.77, 1.5, 2.9}) {
    const double texel_centre = (std::floor(u / texel) + 0.5) * texel;
    const Eigen::Vector2f g = p.sample(texel_centre, -0.3 * texel, 0.0);
    // Texel x holds the height at u = x * texel and is centred at (x + 0.5) * texel.
    const double expected = amplitude * 2 * kPi / wavelength *
                            std::cos(2 * kPi * (texel_centre - 0.5 * texel) / wavelength);
    EXPECT_NEAR(g.x(), expected, 2e-3 * amplitude * 2 * kPi / wavelength);
    EXPECT_NEAR(g.y(), 0.0f, 1e-7f);
  }
  // A footprint of a whole tile averages the slopes away: no shimmer far off.
  EXPECT_NEAR(p.sample(0.3, 0.2, 1000.0).norm(), 0.0f, 1e-6f);
  // The tile repeats, also at UTM-sized coordinates.
  EXPECT_NEAR(
      (p.sample(0.3, 0.2, 0.0) - p.sample(0.3 + 12.8 * 40000, 0.2 - 12.8 * 50000, 0.0)).norm(),
      0.0f, 1e-5f);
}

TEST(SlopePyramid, VarianceIsTheReliefTheFootprintAveragesAway) {
  // h = A sin(2 pi u / L): up close the footprint resolves the slope (no
  // variance); over a whole tile the mean slope is 0 and the variance is the
  // mean of g^2 = (A 2 pi / L)^2 / 2 (central differences: within 0.5 %).
  const double texel = 0.05, amplitude = 0.02;
  const SlopePyramid p(sine_tile(256, texel, 4, amplitude), texel);
  const double g_max = amplitude * 2 * kPi / (256 * texel / 4);
  const double texel_centre = 7.5 * texel;
  EXPECT_LT(p.sample_moments(texel_centre, -0.5 * texel, 0.0).variance, 1e-6 * g_max * g_max);
  const auto far = p.sample_moments(0.3, 0.2, 1000.0);
  EXPECT_NEAR(far.slope.norm(), 0.0f, 1e-6f);
  EXPECT_NEAR(far.variance, 0.5 * g_max * g_max, 5e-3 * 0.5 * g_max * g_max);
  // E[|g|^2] is kept level to level (the mean of every level's second moment).
  auto mean = [](const drift::terrain::Grid<float>& g) {
    double s = 0.0;
    for (float v : g.values()) s += v;
    return s / static_cast<double>(g.size());
  };
  for (int i = 0; i + 1 < p.levels(); ++i)
    EXPECT_NEAR(mean(p.second_moment(i)), mean(p.second_moment(i + 1)), 1e-6 * g_max * g_max);
}

TEST(Ripples, FarRipplesRoughenTheSand) {
  // Far away (a footprint of many tiles) the ripples' mean tilt is gone but
  // their relief becomes Oren-Nayar roughness: sigma = atan(strength x rms
  // slope), in quadrature with the sand's own; up close nearly none is added.
  TerrainSurface s;
  s.ground.roughness = 0.3f;
  NormalDetail layer;
  const double texel = 0.05, amplitude = 0.02;
  layer.slopes = SlopePyramid(sine_tile(256, texel, 4, amplitude), texel);
  layer.strength = 2.0f;
  s.normal_details = {layer};
  const Eigen::Vector3f up(0, 0, 1);
  const double g_rms = amplitude * 2 * kPi / (256 * texel / 4) / std::sqrt(2.0);
  const float far = shade_terrain(s, 0.3, -0.2, up, 1000.0).material.roughness;
  EXPECT_NEAR(far, std::hypot(0.3, std::atan(2.0 * g_rms)), 2e-3);
  const float near = shade_terrain(s, 7.5 * texel, -0.5 * texel, up, 0.0).material.roughness;
  EXPECT_NEAR(near, 0.3f, 1e-3f);
  // No ripples on slip faces: no roughness from them either.
  const float a = static_cast<float>(33.0 * kPi / 180.0);
  const Eigen::Vector3f face(std::sin(a), 0.0f, std::cos(a));
  EXPECT_FLOAT_EQ(shade_terrain(s, 0.3, -0.2, face, 1000.0).material.roughness, 0.3f);
}

TEST(SlopePyramid, RejectsBadTiles) {
  HeightField bad = noise_tile(8, 8);
  bad(3, 3) = NAN;
  EXPECT_THROW(SlopePyramid(bad, 1.0), drift::Error);
  EXPECT_THROW(SlopePyramid(noise_tile(8, 8), 0.0), drift::Error);
  EXPECT_THROW(SlopePyramid(noise_tile(1, 8), 1.0), drift::Error);
}

TEST(Ripples, RotationTurnsTheBumpsAndSlipFacesLoseThem) {
  TerrainSurface s = rippled();
  const Eigen::Vector3f up(0, 0, 1);
  // Unrotated: crests run north-south, so the normal tilts east-west only.
  const Eigen::Vector3f n0 = shade_terrain(s, 0.05, -0.05, up, 0.0).normal;
  EXPECT_GT(std::abs(n0.x()), 0.05f);
  EXPECT_NEAR(n0.y(), 0.0f, 1e-6f);
  // Turned 90 degrees: crests run east-west, the normal tilts north-south.
  s.normal_details[0].rotation_deg = 90.0;
  const Eigen::Vector3f n90 = shade_terrain(s, 0.05, -0.05, up, 0.0).normal;
  EXPECT_NEAR(n90.x(), 0.0f, 1e-5f);
  EXPECT_GT(std::abs(n90.y()), 0.05f);
  // On a 33-degree slip face the ripples are gone.
  const float a = static_cast<float>(33.0 * kPi / 180.0);
  const Eigen::Vector3f face(std::sin(a), 0.0f, std::cos(a));
  EXPECT_NEAR((shade_terrain(s, 0.05, -0.05, face, 0.0).normal - face).norm(), 0.0f, 1e-6f);
}

TEST(Ripples, SnowBuriesThemAndALayerOfColourDoesNot) {
  TerrainSurface s = rippled();
  const Eigen::Vector3f up(0, 0, 1);
  const HeightField everywhere(4, 4, 1.0f, local_georeference(10.0));
  MaterialLayer wet;
  wet.material.wetness = 1.0f;
  wet.mask = everywhere;
  s.layers = {wet};
  EXPECT_GT(std::abs(shade_terrain(s, 0.05, -0.05, up, 0.0).normal.x()), 0.05f);
  Material snow = *material_preset("snow");
  snow.detail = {};  // the snow's own relief would tilt the normal too
  s.layers.push_back(drift::testing::snow_layer(everywhere, {}, snow));
  EXPECT_NEAR((shade_terrain(s, 0.05, -0.05, up, 0.0).normal - up).norm(), 0.0f, 1e-6f);
}

TEST(OrenNayar, LambertAtZeroRoughnessReciprocalAndBackscattering) {
  const Eigen::Vector3f n(0, 0, 1);
  const Eigen::Vector3f wi = Eigen::Vector3f(0.6f, 0.1f, 0.5f).normalized();
  const Eigen::Vector3f wo = Eigen::Vector3f(-0.3f, 0.4f, 0.7f).normalized();
  EXPECT_EQ(oren_nayar_factor(n, wi, wo, 0.0f), 1.0f);
  EXPECT_FLOAT_EQ(oren_nayar_factor(n, wi, wo, 0.4f), oren_nayar_factor(n, wo, wi, 0.4f));
  // Rough surfaces look brighter towards the light (backscatter, the full moon).
  EXPECT_GT(oren_nayar_factor(n, wi, wi, 0.5f), oren_nayar_factor(n, wi, wo, 0.5f));
}

TEST(Snow, CoverBlendsTheMaterialAndDepthRaisesTheSurface) {
  SceneInput in;
  in.terrain = HeightField(32, 32, 100.0f, local_georeference(1.0));
  // Snow on the western half only; 2 m of it.
  HeightField cover(32, 32, 0.0f, local_georeference(1.0));
  HeightField depth(32, 32, 0.0f, local_georeference(1.0));
  for (int row = 0; row < 32; ++row)
    for (int x = 0; x < 16; ++x) cover(x, row) = 1.0f, depth(x, row) = 2.0f;
  Material snow = *material_preset("snow");
  snow.detail = {};  // the snow's own albedo, without its variation
  in.surface.layers.push_back(drift::testing::snow_layer(cover, depth, snow));
  in.height_changes = {{"snow depth", depth}};  // a height change raises the traced surface
  in.sky.constant = true;
  const TerrainScene scene(in);
  Hit west, east;
  const Eigen::Vector3f down(0, 0, -1);
  ASSERT_TRUE(scene.intersect(scene.to_local(Eigen::Vector3d(4.0, -16.0, 500.0)), down, west));
  ASSERT_TRUE(scene.intersect(scene.to_local(Eigen::Vector3d(28.0, -16.0, 500.0)), down, east));
  const int snowy = snow_channel(scene);
  EXPECT_FLOAT_EQ(west.coverage[snowy], 1.0f);
  EXPECT_FLOAT_EQ(east.coverage[snowy], 0.0f);
  // 2 m of snow is opaque: the snow's own albedo (Kubelka-Munk, to rounding).
  EXPECT_NEAR((west.material.albedo - snow.albedo).norm(), 0.0f, 1e-5f);
  EXPECT_NEAR((east.material.albedo - in.surface.ground.albedo).norm(), 0.0f, 1e-6f);
  EXPECT_NEAR(east.distance - west.distance, 2.0f, 1e-3f);
}

TEST(AlbedoMap, ADrapedImageColoursTheGroundAndDecodesSrgb) {
  // A 4 x 4 RGB Byte GeoTIFF, 10 m cells: the western half red (200, 0, 0),
  // the eastern half grey (128, 128, 128).
  const auto path = std::filesystem::temp_directory_path() / "drift_albedo_map.tif";
  drift::terrain::ensure_gdal();
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  GDALDataset* ds = driver->Create(path.c_str(), 4, 4, 3, GDT_Byte, nullptr);
  ASSERT_NE(ds, nullptr);
  double gt[6] = {0.0, 10.0, 0.0, 0.0, 0.0, -10.0};
  ds->SetGeoTransform(gt);
  for (int band = 1; band <= 3; ++band) {
    unsigned char px[16];
    for (int i = 0; i < 16; ++i) px[i] = (i % 4) < 2 ? (band == 1 ? 200 : 0) : 128;
    ASSERT_EQ(ds->GetRasterBand(band)->RasterIO(GF_Write, 0, 0, 4, 4, px, 4, 4, GDT_Byte, 0, 0),
              CE_None);
  }
  GDALClose(ds);
  TerrainSurface s;
  s.albedo_map = read_albedo_map(path);
  const Eigen::Vector3f up(0, 0, 1);
  const Eigen::Vector3f west = shade_terrain(s, 5.0, -15.0, up, kWholeDetail).material.albedo;
  const Eigen::Vector3f east = shade_terrain(s, 35.0, -15.0, up, kWholeDetail).material.albedo;
  const Eigen::Vector3f outside = shade_terrain(s, 500.0, -15.0, up, kWholeDetail).material.albedo;
  EXPECT_NEAR(west.x(), srgb_decode(200.0f / 255.0f), 1e-6f);
  EXPECT_NEAR(west.y(), 0.0f, 1e-6f);
  EXPECT_NEAR(east.y(), srgb_decode(128.0f / 255.0f), 1e-6f);    // 0.216: sRGB decoded
  EXPECT_NEAR((outside - s.ground.albedo).norm(), 0.0f, 1e-6f);  // off the map: the ground colour
  std::filesystem::remove(path);
}

TEST(Snow, MeshCoverageBlendsTheObjectsMaterial) {
  // A horizontal square 10 m above flat ground, fully snowed on one corner's
  // vertices and bare on the others.
  SceneInput in;
  in.terrain = HeightField(16, 16, 0.0f, local_georeference(1.0));
  drift::terrain::PlacedMesh roof;
  roof.mesh.positions = {{0, 0, 10}, {4, 0, 10}, {0, 4, 10}, {4, 4, 10}};
  roof.mesh.triangles = {{0, 1, 2}, {1, 3, 2}};
  roof.position = Eigen::Vector3d(6.0, -10.0, 0.0);
  roof.albedo = {0.3f, 0.2f, 0.1f};
  roof.mesh.vertex_attributes = {{drift::terrain::products::kSnowCoverage, {1, 1, 1, 0}}};
  in.meshes.push_back(roof);
  in.surface.object_layers.push_back(drift::testing::snow_on_objects());
  const TerrainScene scene(in);
  const Eigen::Vector3f down(0, 0, -1);
  Hit near_snowy, near_bare;
  ASSERT_TRUE(scene.intersect(scene.to_local(Eigen::Vector3d(6.2, -9.8, 50.0)), down, near_snowy));
  ASSERT_TRUE(scene.intersect(scene.to_local(Eigen::Vector3d(9.9, -6.1, 50.0)), down, near_bare));
  const int snowy = snow_channel(scene);
  EXPECT_GT(near_snowy.coverage[snowy], 0.95f);
  EXPECT_LT(near_bare.coverage[snowy], 0.1f);
  EXPECT_NEAR((near_snowy.material.albedo - material_preset("snow")->albedo).norm(), 0.0f, 0.05f);
  EXPECT_NEAR((near_bare.material.albedo - roof.albedo).norm(), 0.0f, 0.1f);
}

TEST(Objects, APresetGivesTheirSurfaceItsReliefAndMottle) {
  // Two horizontal 16 m squares 10 m above flat ground: one of plain albedo,
  // one of the `soil` preset (clods over 1 m, a mottled tone), sampled by
  // vertical rays on a 0.25 m lattice, from above and from below.
  SceneInput in;
  in.terrain = HeightField(64, 64, 0.0f, local_georeference(1.0));
  auto square = [](double east, const std::string& material) {
    drift::terrain::PlacedMesh m;
    m.mesh.positions = {{0, 0, 10}, {16, 0, 10}, {0, 16, 10}, {16, 16, 10}};
    m.mesh.triangles = {{0, 1, 2}, {1, 3, 2}};
    m.position = Eigen::Vector3d(east, -40.0, 0.0);
    m.material = material;
    if (!material.empty()) m.albedo = material_preset(material)->albedo;
    return m;
  };
  in.meshes = {square(4.0, ""), square(36.0, "soil")};
  const TerrainScene scene(in);
  struct Stats {
    double mean = 0, sq = 0, tilt = 0;
    int n = 0, facing = 0;
  };
  auto sample = [&](double east, float dz) {
    Stats s;
    for (double y = -38.0; y < -26.0; y += 0.25) {
      for (double x = east + 2.0; x < east + 14.0; x += 0.25) {
        Hit h;
        const Eigen::Vector3f d(0, 0, dz);
        EXPECT_TRUE(scene.intersect(scene.to_local(Eigen::Vector3d(x, y, 10.0 - 5.0 * dz)), d, h));
        const double a = h.material.albedo.y();
        s.mean += a, s.sq += a * a, s.tilt += h.normal.head<2>().norm(), ++s.n;
        s.facing += h.normal.dot(d) < 0.0f;
      }
    }
    s.mean /= s.n, s.sq /= s.n, s.tilt /= s.n;
    return s;
  };
  const Stats plain = sample(4.0, -1.0f), soil = sample(36.0, -1.0f), under = sample(36.0, 1.0f);
  // Plain: one albedo, the face's own normal.
  EXPECT_NEAR(plain.sq - plain.mean * plain.mean, 0.0, 1e-12);
  EXPECT_NEAR(plain.tilt, 0.0, 1e-6);
  // Soil: its tone varies about the preset's (variation 0.2; the mean of a
  // 12 m patch is one draw of octaves up to 128 m, so only near it) and its
  // relief tilts the shading normal (bump 0.35), from above and below alike.
  const double albedo = material_preset("soil")->albedo.y();
  EXPECT_NEAR(soil.mean, albedo, 0.4 * albedo);
  EXPECT_GT(std::sqrt(soil.sq - soil.mean * soil.mean), 0.05 * albedo);
  EXPECT_GT(soil.tilt, 0.1);
  EXPECT_GT(under.tilt, 0.1);
  EXPECT_EQ(soil.facing, soil.n);
  EXPECT_EQ(under.facing, under.n);
}

TEST(HeightChanges, EachRaisesTheTracedSurfaceInTurnAndNoneLowersIt) {
  // Flat ground at 100 m; one change lays 1 m everywhere, a second 0.5 m on
  // the western half and -3 m (counts as none) on the eastern half.
  SceneInput in;
  in.terrain = HeightField(32, 32, 100.0f, local_georeference(1.0));
  HeightField second(32, 32, -3.0f, local_georeference(1.0));
  for (int row = 0; row < 32; ++row)
    for (int x = 0; x < 16; ++x) second(x, row) = 0.5f;
  in.height_changes = {{"one", HeightField(32, 32, 1.0f, local_georeference(1.0))},
                       {"two", second}};
  const TerrainScene scene(in);
  const Eigen::Vector3f down(0, 0, -1);
  Hit west, east;
  ASSERT_TRUE(scene.intersect(scene.to_local(Eigen::Vector3d(4.0, -16.0, 500.0)), down, west));
  ASSERT_TRUE(scene.intersect(scene.to_local(Eigen::Vector3d(28.0, -16.0, 500.0)), down, east));
  EXPECT_NEAR(scene.origin().z() + west.position.z(), 101.5, 1e-3);
  EXPECT_NEAR(scene.origin().z() + east.position.z(), 101.0, 1e-3);
}
