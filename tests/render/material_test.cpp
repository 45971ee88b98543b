// Material presets, rules by altitude and slope, and mask layers.
#include "render/material.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "render/surface.h"
#include "render/terrain_scene.h"
#include "terrain/error.h"
#include "tests/render/snow_layer.h"

using namespace drift::render;
using drift::terrain::HeightField;
using drift::terrain::local_georeference;

// A footprint so wide that the ground's procedural detail is its mean
// (albedo factor 1, no relief: render/ground_detail.h), for tests of the
// material stack itself.
constexpr double kWholeDetail = 1e6;

TEST(MaterialPresets, KnownNamesWithPlausibleAlbedos) {
  EXPECT_EQ(material_preset_names(),
            "rock, dark_rock, scree, meadow, dwarf_pine, forest, sand, mud, soil, grass, snow");
  auto lum = [](const Material& m) {
    return 0.2126f * m.albedo.x() + 0.7152f * m.albedo.y() + 0.0722f * m.albedo.z();
  };
  // The land classes inside their measured visible ranges (material.cpp).
  // Andesite, tuff and hornfels: 0.08-0.15 in the visible (ASTER/ECOSTRESS,
  // USGS libraries); scree of the same rock, fresher, at most 0.16.
  EXPECT_GT(lum(*material_preset("dark_rock")), 0.08f);
  EXPECT_LT(lum(*material_preset("dark_rock")), 0.15f);
  EXPECT_LT(lum(*material_preset("scree")), 0.16f);
  EXPECT_GT(lum(*material_preset("scree")), lum(*material_preset("dark_rock")));
  EXPECT_LT(lum(*material_preset("dwarf_pine")), 0.05f);
  EXPECT_LT(lum(*material_preset("forest")), 0.05f);
  EXPECT_GT(material_preset("dwarf_pine")->albedo.y(), material_preset("dwarf_pine")->albedo.x());
  EXPECT_GT(material_preset("meadow")->albedo.x(), material_preset("meadow")->albedo.z());
  for (const char* name : {"rock", "dark_rock", "scree", "meadow", "dwarf_pine", "forest"}) {
    EXPECT_GT(material_preset(name)->detail.variation, 0.0f) << name;
    EXPECT_GT(material_preset(name)->detail.bump, 0.0f) << name;
    EXPECT_LE(material_preset(name)->detail.scale, 10.0f) << name;  // below a 10 m cell
  }
  EXPECT_GT(lum(*material_preset("snow")), 0.85f);
  EXPECT_GT(lum(*material_preset("sand")), lum(*material_preset("rock")));
  EXPECT_LT(lum(*material_preset("grass")), 0.15f);
  EXPECT_GT(material_preset("grass")->albedo.y(), material_preset("grass")->albedo.x());
  EXPECT_GT(material_preset("mud")->wetness, 0.5f);
  EXPECT_FALSE(material_preset("lava").has_value());
}

TEST(MaterialRules, SoftRangesAndLaterRulesWin) {
  const SoftRange r{1000.0f, 2000.0f, 100.0f};
  EXPECT_EQ(r.weight(900.0f), 0.0f);
  EXPECT_FLOAT_EQ(r.weight(1000.0f), 0.5f);  // the band is centred on the bound
  EXPECT_EQ(r.weight(1500.0f), 1.0f);
  EXPECT_FLOAT_EQ(r.weight(2000.0f), 0.5f);
  EXPECT_EQ(r.weight(2100.0f), 0.0f);
  EXPECT_EQ(SoftRange{}.weight(-1e9f), 1.0f);  // open on both sides

  // Grass below 2000 m, rock on slopes over 35 degrees (wins where both hold).
  MaterialRule grass, rock;
  grass.material = full_override(*material_preset("grass"));
  grass.material.detail = GroundDetail{};  // the stack alone, no sub-cell relief
  grass.altitude = {-1e9f, 2000.0f, 100.0f};
  rock.material.albedo = material_preset("rock")->albedo;  // colour only
  rock.slope = {35.0f, 90.0f, 0.0f};
  TerrainSurface surface;
  surface.ground = Material{{0.5f, 0.5f, 0.5f}, 0.2f, 0.0f};
  surface.rules = {grass, rock};
  const Material& base = surface.ground;
  auto apply_rules = [&](float altitude, float slope) {
    return shade_terrain(surface, 0.0, 0.0, Eigen::Vector3f(0, 0, 1), kWholeDetail,
                         {altitude, slope})
        .material;
  };
  EXPECT_EQ(apply_rules(1500.0f, 10.0f).albedo, material_preset("grass")->albedo);
  const Material steep_low = apply_rules(1500.0f, 50.0f);
  EXPECT_EQ(steep_low.albedo, material_preset("rock")->albedo);
  EXPECT_EQ(steep_low.roughness, material_preset("grass")->roughness);  // rock set only colour
  EXPECT_EQ(apply_rules(3000.0f, 10.0f).albedo, base.albedo);
  // Half way up the tree line band: half grass.
  const Material edge = apply_rules(2000.0f, 10.0f);
  EXPECT_NEAR(edge.albedo.x(), 0.5f * (base.albedo.x() + material_preset("grass")->albedo.x()),
              1e-6f);
}

TEST(MaterialRules, PatchesEndInCrispEdgesAndKeepTheShare) {
  // Snow at weight 0.3 (a third of the way into its altitude band): blended,
  // a translucent 0.3 everywhere; as patches of 15 m, up close snow or no
  // snow (crisp edges: under 10 % of the ground in between) covering 0.3 of
  // the ground, and from afar (a 60 m footprint) the blend's 0.3 exactly.
  MaterialRule snow;
  snow.material = full_override(*material_preset("snow"));
  snow.material.detail = GroundDetail{};
  snow.altitude = {2500.0f, 1e9f, 200.0f};
  snow.patch_size = 15.0f;
  TerrainSurface surface;
  surface.ground = Material{{0.1f, 0.1f, 0.1f}, 0.2f, 0.0f};
  surface.rules = {snow};
  const float w = snow.weight(2450.0f, 10.0f);
  ASSERT_GT(w, 0.1f);
  ASSERT_LT(w, 0.9f);
  auto share = [&](double x, double y, double footprint) {  // snow's share of the albedo
    const Material m =
        shade_terrain(surface, x, y, Eigen::Vector3f(0, 0, 1), footprint, {2450.0f, 10.0f})
            .material;
    return (m.albedo.x() - 0.1f) / (material_preset("snow")->albedo.x() - 0.1f);
  };
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 5000.0);
  double sum = 0;
  int between = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const float s = share(u(rng), u(rng), 0.0);
    sum += s;
    between += s > 0.05f && s < 0.95f;
  }
  EXPECT_NEAR(sum / n, w, 0.03);
  EXPECT_LT(between, n / 10);
  EXPECT_NEAR(share(12.0, 34.0, 60.0), w, 1e-5);
}

TEST(MaterialRules, TerrainHitsSeeTrueSlopeAndAltitude) {
  // A plane rising 0.5 m per metre east (26.6 degrees) at 1000 m, rendered
  // with exaggeration 2 (45 degrees on screen): rules judge the real relief.
  SceneInput in;
  in.terrain = HeightField(64, 64, 0.0f, local_georeference(1.0));
  for (int r = 0; r < 64; ++r)
    for (int x = 0; x < 64; ++x) in.terrain(x, r) = 1000.0f + 0.5f * x;
  in.vertical_exaggeration = 2.0;
  MaterialRule steep, high;
  steep.material.roughness = 1.0f;
  steep.slope = {30.0f, 90.0f, 0.0f};  // not met: the real slope is 26.6
  high.material.wetness = 1.0f;
  high.altitude = {1016.0f, 1e9f, 0.0f};  // the eastern half
  in.surface.rules = {steep, high};
  const TerrainScene scene(in);
  Hit west, east;
  const Eigen::Vector3f down(0, 0, -1);
  ASSERT_TRUE(scene.intersect(scene.to_local(Eigen::Vector3d(10.0, -32.0, 5000.0)), down, west));
  ASSERT_TRUE(scene.intersect(scene.to_local(Eigen::Vector3d(50.0, -32.0, 5000.0)), down, east));
  EXPECT_EQ(west.material.roughness, 0.0f);
  EXPECT_EQ(west.material.wetness, 0.0f);
  EXPECT_EQ(east.material.wetness, 1.0f);
  // 27 degrees is steep enough for a rule at 25.
  in.surface.rules[0].slope = {25.0f, 90.0f, 0.0f};
  const TerrainScene scene25(in);
  ASSERT_TRUE(
      scene25.intersect(scene25.to_local(Eigen::Vector3d(10.0, -32.0, 5000.0)), down, west));
  EXPECT_EQ(west.material.roughness, 1.0f);
}

TEST(MaterialLayers, MasksBlendInOrderUnderSnow) {
  TerrainSurface s;
  // Sand where the mask is 1 (western half), 0.5 in the middle column.
  MaterialLayer sand;
  sand.material = full_override(*material_preset("sand"));
  sand.mask = HeightField(4, 4, 0.0f, local_georeference(10.0));
  for (int r = 0; r < 4; ++r) sand.mask(0, r) = sand.mask(1, r) = 1.0f;
  // Wetness everywhere over it, at 0.6 opacity.
  MaterialLayer wet;
  wet.material.wetness = 1.0f;
  wet.mask = HeightField(4, 4, 1.0f, local_georeference(10.0));
  wet.opacity = 0.6f;
  s.layers = {sand, wet};
  const Eigen::Vector3f up(0, 0, 1);
  const Material west = shade_terrain(s, 5.0, -15.0, up, kWholeDetail).material;
  const Material east = shade_terrain(s, 35.0, -15.0, up, kWholeDetail).material;
  EXPECT_EQ(west.albedo, material_preset("sand")->albedo);
  EXPECT_FLOAT_EQ(west.wetness, 0.6f);
  EXPECT_EQ(east.albedo, s.ground.albedo);
  EXPECT_FLOAT_EQ(east.wetness, 0.6f);
  EXPECT_EQ(shade_terrain(s, 500.0, -15.0, up, kWholeDetail).material.wetness,
            0.0f);  // off the masks
  // Snow covers everything.
  s.layers.push_back(drift::testing::snow_layer(HeightField(4, 4, 1.0f, local_georeference(10.0))));
  EXPECT_EQ(shade_terrain(s, 5.0, -15.0, up, kWholeDetail).material.albedo,
            material_preset("snow")->albedo);
}

TEST(Coverage, SharesFollowTheStackAndSumToOne) {
  // Base "rock"; a grass rule below 2000 m; a layer "wet" by a mask at 0.5
  // opacity; a second rule "rock" on cliffs shares the base's channel; snow.
  TerrainSurface s;
  s.ground_name = "rock";
  MaterialRule grass, cliffs;
  grass.name = "grass";
  grass.material = full_override(*material_preset("grass"));
  grass.altitude = {-1e9f, 2000.0f, 0.0f};
  cliffs.name = "rock";
  cliffs.material = full_override(*material_preset("rock"));
  cliffs.slope = {40.0f, 90.0f, 0.0f};
  s.rules = {grass, cliffs};
  MaterialLayer wet;
  wet.name = "wet";
  wet.material.wetness = 1.0f;
  wet.mask = HeightField(4, 4, 1.0f, local_georeference(10.0));
  wet.opacity = 0.5f;
  s.layers = {wet, drift::testing::snow_layer(HeightField(4, 4, 0.2f, local_georeference(10.0)))};
  const CoverageChannels c = coverage_channels(s);
  ASSERT_EQ(c.names, (std::vector<std::string>{"rock", "grass", "wet", "snow"}));
  EXPECT_EQ(c.rules, (std::vector<int>{1, 0}));
  const Eigen::Vector3f up(0, 0, 1);
  auto shares = [&](float altitude, float slope) {
    return shade_terrain(s, 5.0, -15.0, up, kWholeDetail, {altitude, slope}, &c).coverage;
  };
  // Low and gentle: grass, then half of it under the wet layer, then 20 % snow.
  const Coverage low = shares(1000.0f, 10.0f);
  EXPECT_FLOAT_EQ(low[0], 0.0f);
  EXPECT_FLOAT_EQ(low[1], 0.5f * 0.8f);
  EXPECT_FLOAT_EQ(low[2], 0.5f * 0.8f);
  EXPECT_FLOAT_EQ(low[3], 0.2f);
  // Low cliff: the cliff rule takes the grass's share back to "rock".
  const Coverage cliff = shares(1000.0f, 60.0f);
  EXPECT_FLOAT_EQ(cliff[0], 0.4f);
  EXPECT_FLOAT_EQ(cliff[1], 0.0f);
  for (const Coverage& k : {low, cliff, shares(3000.0f, 20.0f)}) {
    float sum = 0.0f;
    for (float v : k) sum += v;
    EXPECT_NEAR(sum, 1.0f, 1e-6f);
  }
  // More names than channels is an error that says what to do.
  for (int i = 0; i < kMaxCoverage; ++i) {
    s.rules.push_back(grass);
    s.rules.back().name = "r" + std::to_string(i);
  }
  EXPECT_THROW(coverage_channels(s), drift::Error);
}

TEST(SnowLayer, ThinSnowShowsTheGroundThrough) {
  const Eigen::Vector3f snow(0.9f, 0.92f, 0.95f), rock(0.1f, 0.09f, 0.08f);
  // Limits: no snow is the ground, a deep pack is the snow's own albedo.
  EXPECT_NEAR((layer_albedo(snow, rock, 0.0f) - rock).norm(), 0.0f, 1e-6f);
  EXPECT_NEAR((layer_albedo(snow, rock, 1e4f) - snow).norm(), 0.0f, 1e-5f);
  // Kubelka-Munk over black ground, R = 1 / (a + b coth(b S d)), by hand for
  // R_inf = 0.9, S d = 4: a = 1.005556, b = 0.105409, coth(0.421637) = 2.51085.
  const Eigen::Vector3f black = Eigen::Vector3f::Zero();
  EXPECT_NEAR(layer_albedo(Eigen::Vector3f::Constant(0.9f), black, 4.0f).x(),
              1.0 / (1.005556 + 0.105409 * 2.51085), 1e-4);
  // Deeper snow moves monotonically from the ground to the snow, from above
  // over dark rock and from below over a ground brighter than snow.
  const Eigen::Vector3f bright = Eigen::Vector3f::Constant(0.97f);
  float last_dark = 0.0f, last_bright = 1.0f;
  for (float d = 0.5f; d < 20.0f; d *= 1.5f) {
    const float dark = layer_albedo(snow, rock, d).x(), over = layer_albedo(snow, bright, d).x();
    EXPECT_GT(dark, last_dark);
    EXPECT_LT(over, last_bright);
    last_dark = dark, last_bright = over;
  }
}

TEST(SnowLayer, ADepthRasterMakesThinSnowGrey) {
  // Full cover everywhere; depth 2 mm in the west, 20 cm in the east.
  TerrainSurface s;
  s.ground.albedo = Eigen::Vector3f::Constant(0.05f);
  HeightField depth(4, 4, 0.002f, drift::terrain::local_georeference(1.0));
  for (int row = 0; row < 4; ++row) depth(3, row) = depth(2, row) = 0.2f;
  s.layers.push_back(drift::testing::snow_layer(
      HeightField(4, 4, 1.0f, drift::terrain::local_georeference(1.0)), depth));
  const Eigen::Vector3f up(0, 0, 1);
  const float thin = shade_terrain(s, 0.5, -1.5, up, kWholeDetail).material.albedo.x();
  const float deep = shade_terrain(s, 3.5, -1.5, up, kWholeDetail).material.albedo.x();
  EXPECT_NEAR(deep, material_preset("snow")->albedo.x(), 1e-3f);
  EXPECT_LT(thin, 0.6f * deep);
  EXPECT_GT(thin, s.ground.albedo.x());
}
