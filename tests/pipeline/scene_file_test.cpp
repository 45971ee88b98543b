// Scene files: every mistake names the key and the file; the CLI exits 1 and
// writes nothing.
#include "pipeline/scene_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "pipeline/scene_products.h"
#include "pipeline/toml_section.h"
#include "render/image_io.h"
#include "render/material.h"
#include "render/solar_position.h"
#include "render/surface.h"
#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/products.h"
#include "terrain/raster_io.h"

namespace fs = std::filesystem;

namespace {

fs::path write_scene(const std::string& name, const std::string& text) {
  // One folder per test: CTest runs test cases in parallel processes.
  const fs::path dir = fs::temp_directory_path() / "drift_scene_tests" /
                       ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::create_directories(dir);
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

// The error message of reading `text` as a scene (empty if it parsed).
std::string error_of(const std::string& text) {
  const fs::path p = write_scene("s.toml", text);
  try {
    drift::pipeline::read_scene_file(p);
  } catch (const drift::Error& e) {
    return e.what();
  }
  return "";
}

const char* kTerrain = "[terrain]\nraster = \"dem.tif\"\n";

// Whether the scene kTerrain + `rest` is refused with an error naming `what`
// (the failure shows the error).
::testing::AssertionResult refused_naming(const std::string& rest, const std::string& what) {
  const std::string e = error_of(std::string(kTerrain) + rest);
  if (e.find(what) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "the error does not name '" << what << "': '" << e << "'";
}

// `name` holding the scene kTerrain + `rest`.
fs::path terrain_scene(const std::string& name, const std::string& rest) {
  return write_scene(name, std::string(kTerrain) + rest);
}

}  // namespace

TEST(SceneFile, ReadsEveryKey) {
  const fs::path p = terrain_scene("full.toml",
                                   "exaggeration = 1.5\ncolor = [0.3, 0.2, 0.1]\n"
                                   "[sun]\nazimuth = 200\nelevation = 12.5\n"
                                   "[sky]\nlight_shafts = true\nshaft_steps = 24\n"
                                   "[camera]\nfrom = [1, 2, 3]\nto = [4, 5, 6]\nfov = 30\n"
                                   "[render]\nwidth = 320\nheight = 200\nspp = 7\nseed = 9\n"
                                   "sample_sky = false\nnoise_target = 0.02\nmin_spp = 8\n"
                                   "[output]\nfiles = [\"a.png\", \"a.exr\"]\nexposure = -1\n");
  const auto s = drift::pipeline::read_scene_file(p);
  EXPECT_EQ(s.terrain_raster, p.parent_path() / "dem.tif");
  EXPECT_DOUBLE_EQ(s.input.vertical_exaggeration, 1.5);
  EXPECT_DOUBLE_EQ(s.input.sun.elevation_deg, 12.5);
  EXPECT_TRUE(s.input.sky.light_shafts);
  EXPECT_EQ(s.input.sky.shaft_steps, 24);
  ASSERT_TRUE(s.input.camera.has_value());
  EXPECT_DOUBLE_EQ(s.input.camera->to.z(), 6.0);
  EXPECT_EQ(s.settings.width, 320);
  EXPECT_EQ(s.settings.samples_per_pixel, 7);
  EXPECT_EQ(s.settings.seed, 9u);
  EXPECT_FALSE(s.settings.sample_sky);
  EXPECT_FLOAT_EQ(s.settings.noise_target, 0.02f);
  EXPECT_EQ(s.settings.min_samples, 8);
  EXPECT_EQ(s.outputs.size(), 2u);
  EXPECT_DOUBLE_EQ(s.display.exposure_ev, -1.0);
}

TEST(SceneFile, UnknownKeyNamesKeyAndFile) {
  const std::string e = error_of(std::string(kTerrain) + "[sun]\nazimuht = 3\n");
  EXPECT_NE(e.find("sun.azimuht"), std::string::npos) << e;
  EXPECT_NE(e.find("s.toml:4"), std::string::npos) << e;  // the line of the bad key
}

TEST(SceneFile, UnknownSectionIsAnError) {
  EXPECT_TRUE(refused_naming("[camrea]\nfov = 3\n", "camrea"));
}

TEST(SceneFile, UnknownSectionListsEverySectionFromTheTables) {
  // The list is made from the stages' table (pipeline/scene_products.h) and
  // the renderer's own sections, in reading order; every section it names is
  // one the reader accepts.
  const std::string e = error_of(std::string(kTerrain) + "[camrea]\nfov = 3\n");
  EXPECT_NE(e.find("(known: terrain, snow, ripples, sun, sky, clouds, camera, objects, render, "
                   "output)"),
            std::string::npos)
      << e;
  for (const drift::pipeline::StageSection& stage : drift::pipeline::stage_sections())
    EXPECT_NE(e.find(std::string(", ") + stage.name + ","), std::string::npos) << stage.name;
  for (const std::string& section : drift::pipeline::scene_sections()) {
    if (section == "terrain") continue;
    const std::string ok = error_of(std::string(kTerrain) + "[" + section + "]\n");
    EXPECT_EQ(ok.find("unknown section"), std::string::npos) << section << ": " << ok;
  }
}

TEST(SceneFile, StageFlagsOverrideTheirSectionsFiles) {
  // Each product-file key of a stage's section lands in product_files under
  // "section.key", the name drift render's flag overrides.
  for (const drift::pipeline::StageSection& stage : drift::pipeline::stage_sections()) {
    std::string text = std::string(kTerrain) + "[" + stage.name + "]\n";
    for (const auto& file : stage.files) text += std::string(file.key) + " = \"f.tif\"\n";
    const auto s = drift::pipeline::read_scene_file(write_scene("f.toml", text));
    for (const auto& file : stage.files) {
      EXPECT_EQ(s.product_file(drift::pipeline::product_key(stage, file)).filename(), "f.tif")
          << stage.name << "." << file.key;
      EXPECT_EQ(std::string(file.flag).rfind("--", 0), 0u) << file.flag;
    }
    EXPECT_TRUE(s.loads(stage.name)) << stage.name;
  }
}

TEST(SceneFile, WrongTypeIsAnError) {
  const std::string e = error_of(std::string(kTerrain) + "[render]\nspp = \"many\"\n");
  EXPECT_NE(e.find("render.spp"), std::string::npos) << e;
  EXPECT_NE(e.find("integer"), std::string::npos) << e;
}

TEST(SceneFile, OutOfRangeValuesAreErrors) {
  EXPECT_TRUE(refused_naming("[render]\nspp = -4\n", "render.spp"));
  EXPECT_TRUE(refused_naming("[render]\nwidth = 0\n", "render.width"));
  EXPECT_TRUE(refused_naming("[sun]\nelevation = nan\n", "sun.elevation"));
  EXPECT_TRUE(refused_naming("[sky]\nshaft_steps = 0\n", "sky.shaft_steps"));
  EXPECT_TRUE(refused_naming("[sky]\nvisibility = 500\n", "sky.visibility"));
  EXPECT_TRUE(refused_naming("[sky]\nvisibility = 20\nhaze = 2\n", "not both"));
  EXPECT_TRUE(
      refused_naming("[camera]\nfrom = [0, 0, 1]\nto = [0, 1, 1]\nfov = 180\n", "camera.fov"));
}

TEST(SceneFile, EveryValueErrorNamesItsLine) {
  // Checks that read a table as a whole or two keys together keep the line.
  const std::pair<std::string, std::string> cases[] = {
      {"[sun]\ndate = \"2026-01-01\"\n", "s.toml:3"},
      {"[sun]\nazimuth = 3\ndate = \"2026-01-01\"\ntime = \"10:00\"\n", "s.toml:3"},
      {"[sky]\nmodel = \"cloudy\"\n", "s.toml:4"},
      {"[sky]\nhaze = 2\nvisibility = 20\n", "s.toml:5"},
      {"[camera]\nfrom = [0, 0, 1]\n", "s.toml:3"},
      {"[camera]\nfrom = [0, 0, 1]\nto = [0, 1, 1]\nf_number = 2\n", "s.toml:6"},
      {"[ripples]\ncell = 1\n", "s.toml:3"},
      {"[ripples]\nraster = \"r.tif\"\nfade_slope = [30, 20]\n", "s.toml:5"},
      {"[output]\ntone = \"aces\"\n", "s.toml:4"},
      {"[output]\nwhite_balance = \"tungsten\"\n", "s.toml:4"},
  };
  for (const auto& [text, where] : cases) {
    const std::string e = error_of(std::string(kTerrain) + text);
    EXPECT_NE(e.find(where), std::string::npos) << text << " -> " << e;
  }
  const std::string e = error_of("[terrain]\nrepeat = 2\nraster = \"dem.tif\"\n");
  EXPECT_NE(e.find("s.toml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("terrain.repeat"), std::string::npos) << e;
}

TEST(SceneFile, SeedTakesTheCommandLinesSixtyFourBitRange) {
  const auto seed_of = [](const std::string& value) {
    const fs::path p = terrain_scene("seed.toml", "[render]\nseed = " + value + "\n");
    return drift::pipeline::read_scene_file(p).settings.seed;
  };
  EXPECT_EQ(seed_of("0"), 0u);
  EXPECT_EQ(seed_of("4294967296"), 4294967296u);  // beyond 2^31 - 1: seeds are 64-bit
  EXPECT_EQ(seed_of("9223372036854775807"), 9223372036854775807u);
  EXPECT_EQ(seed_of("\"18446744073709551615\""), 18446744073709551615u);
  for (const char* bad : {"-1", "\"18446744073709551616\"", "\"12a\"", "1.5"}) {
    const std::string e = error_of(std::string(kTerrain) + "[render]\nseed = " + bad + "\n");
    EXPECT_NE(e.find("render.seed"), std::string::npos) << bad << " -> " << e;
  }
}

TEST(SceneFile, UnknownKeyNamesTheDocumentOfItsTable) {
  drift::pipeline::Section s(nullptr, "x", "f.toml", "docs/other.md");
  toml::table t{{"a", 1}};
  drift::pipeline::Section with(&t, "marks", "f.toml", "docs/marks.md");
  try {
    with.finish();
    FAIL() << "an unread key must be reported";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("docs/marks.md"), std::string::npos) << e.what();
  }
  s.finish();  // no table: nothing to report
}

TEST(SceneFile, SyntaxErrorNamesFileAndLine) {
  const std::string e = error_of(std::string(kTerrain) + "[sun\nazimuth = 3\n");
  EXPECT_NE(e.find("s.toml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("syntax"), std::string::npos) << e;
}

TEST(SceneFile, MissingRasterIsAnError) {
  EXPECT_NE(error_of("[sun]\nazimuth = 3\n").find("raster"), std::string::npos);
}

TEST(RenderCommand, BadSceneExitsOneAndWritesNothing) {
  const fs::path scene = terrain_scene("bad.toml", "[render]\nspp = 0\n");
  const fs::path out = scene.parent_path() / "bad_out.png";
  fs::remove(out);
  const std::string cmd = std::string(DRIFT_EXECUTABLE) + " render " + scene.string() + " -o " +
                          out.string() + " 2>/dev/null";
  const int status = std::system(cmd.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 1);
  EXPECT_FALSE(fs::exists(out));
}

TEST(RenderCommand, FailedRunKeepsExistingOutput) {
  // The raster is missing: the run fails after parsing and must not touch out.png.
  const fs::path scene = terrain_scene("missing_raster.toml", "");
  const fs::path out = scene.parent_path() / "keep.png";
  std::ofstream(out) << "good";
  const std::string cmd = std::string(DRIFT_EXECUTABLE) + " render " + scene.string() + " -o " +
                          out.string() + " 2>/dev/null";
  EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 1);
  std::ifstream in(out);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "good");
}

TEST(RenderCommand, BadSizeIsAUsageError) {
  const fs::path scene = terrain_scene("ok.toml", "");
  const std::string cmd = std::string(DRIFT_EXECUTABLE) + " render " + scene.string() +
                          " --size 0x10 -o " + (fs::temp_directory_path() / "x.png").string() +
                          " 2>/dev/null";
  EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 2);
}

// --set before the scene file, as the gallery's Makefile gives it: one
// NAME=VALUE a flag, so the scene stays the scene; the value reaches the paths.
TEST(RenderCommand, SetGivesAVariableBeforeOrAfterTheScene) {
  const fs::path scene = write_scene("vars.toml", "[terrain]\nraster = \"${DIR}/dem.tif\"\n");
  const fs::path log = scene.parent_path() / "log.txt";
  const std::string out = (scene.parent_path() / "x.png").string();
  const std::string drift = std::string(DRIFT_EXECUTABLE) + " render ";
  for (const std::string& args : {"--set DIR=/no/such " + scene.string() + " -o " + out,
                                  scene.string() + " --set DIR=/no/such -o " + out}) {
    const std::string cmd = drift + args + " 2>" + log.string();
    EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 1) << args;
    std::ifstream in(log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("/no/such/dem.tif"), std::string::npos) << args << ": " << text;
  }
  const std::string bad = drift + "--set 9X=1 " + scene.string() + " -o " + out + " 2>/dev/null";
  EXPECT_EQ(WEXITSTATUS(std::system(bad.c_str())), 2);
}

TEST(SceneFile, ObjectsAreLoadedAndPlaced) {
  const fs::path dir = fs::temp_directory_path() / "drift_scene_tests" / "objects";
  fs::create_directories(dir);
  std::ofstream(dir / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const fs::path p =
      terrain_scene("obj.toml", "[[objects]]\nmesh = \"" + (dir / "tri.obj").string() +
                                    "\"\nposition = [100, 200, 5]\nscale = 2\nrotate_z = 90\n");
  const auto s = drift::pipeline::read_scene_file(p);
  ASSERT_EQ(s.input.meshes.size(), 1u);
  const auto& v = s.input.meshes[0].mesh.positions;
  // (1, 0, 0) scaled by 2 and turned 90 degrees anticlockwise is (0, 2, 0),
  // standing at the object's position.
  EXPECT_NEAR(v[1].x(), 0.0f, 1e-5f);
  EXPECT_NEAR(v[1].y(), 2.0f, 1e-5f);
  EXPECT_NEAR(v[1].z(), 0.0f, 1e-5f);
  EXPECT_EQ(s.input.meshes[0].position, Eigen::Vector3d(100, 200, 5));
}

TEST(SceneFile, ObjectsTakeAMaterialPresetWhoseColourTheirOwnOverrides) {
  const fs::path obj = write_scene("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string mesh = "[[objects]]\nmesh = \"" + obj.string() + "\"\n";
  const auto s = drift::pipeline::read_scene_file(
      terrain_scene("obj_material.toml", mesh + "material = \"soil\"\n" + mesh +
                                             "material = \"soil\"\ncolor = [0.3, 0.2, 0.1]\n" +
                                             mesh + "color = [0.3, 0.2, 0.1]\n"));
  ASSERT_EQ(s.input.meshes.size(), 3u);
  EXPECT_EQ(s.input.meshes[0].material, "soil");
  EXPECT_EQ(s.input.meshes[0].albedo, drift::render::material_preset("soil")->albedo);
  EXPECT_EQ(s.input.meshes[1].material, "soil");
  EXPECT_EQ(s.input.meshes[1].albedo, Eigen::Vector3f(0.3f, 0.2f, 0.1f));
  EXPECT_EQ(s.input.meshes[2].material, "");
  const std::string e = error_of(std::string(kTerrain) + mesh + "material = \"clay\"\n");
  EXPECT_NE(e.find("objects.material"), std::string::npos) << e;
  EXPECT_NE(e.find("'clay'"), std::string::npos) << e;
  EXPECT_NE(e.find("soil"), std::string::npos) << e;
}

TEST(SceneFile, ReadsSnowAndRippleLayers) {
  const fs::path p =
      terrain_scene("layers.toml",
                    "roughness = 0.4\n"
                    "[snow]\ncover = \"cover.tif\"\ndepth = \"/abs/depth.tif\"\n"
                    "color = [0.9, 0.9, 0.95]\n"
                    "[ripples]\nraster = \"ripples.tif\"\ncell = 0.05\nrotation = 30\n"
                    "strength = 2\nfade_slope = [20, 30]\n");
  const auto s = drift::pipeline::read_scene_file(p);
  EXPECT_EQ(s.product_file("snow.cover"), p.parent_path() / "cover.tif");
  EXPECT_EQ(s.product_file("snow.depth"), fs::path("/abs/depth.tif"));
  EXPECT_EQ(s.product_file("snow.objects"), fs::path());
  EXPECT_EQ(s.product_file("ripples.raster"), p.parent_path() / "ripples.tif");
  EXPECT_TRUE(s.loads("snow"));
  EXPECT_TRUE(s.loads("ripples"));
  ASSERT_EQ(s.input.surface.normal_details.size(), 1u);
  EXPECT_DOUBLE_EQ(s.input.surface.normal_details[0].rotation_deg, 30.0);
  EXPECT_FLOAT_EQ(s.input.surface.normal_details[0].fade_end_deg, 30.0f);
  EXPECT_FLOAT_EQ(s.input.surface.ground.roughness, 0.4f);
}

TEST(SceneFile, SnowProductsBecomeTheLastMaterialLayerWithTheSnowsLook) {
  // [snow] cover is a material mask of the snow material laid over the
  // scene's own layers, translucent by the depth that also raises the
  // ground, in flakes where thin, burying ripples; objects take the same
  // snow by their snow-coverage attribute.
  const fs::path p = terrain_scene("snow.toml",
                                   "[[terrain.layer]]\nmask = \"wet.tif\"\nwetness = 1\n"
                                   "[snow]\ncover = \"snow.tif\"\ndepth = \"snow.tif\"\n"
                                   "color = [0.8, 0.85, 0.9]\nroughness = 0.3\nscattering = 250\n"
                                   "cover_outside = 1\n");
  drift::terrain::write_geotiff(
      drift::terrain::HeightField(2, 2, 0.5f, drift::terrain::local_georeference(1.0)),
      p.parent_path() / "snow.tif");
  auto s = drift::pipeline::read_scene_file(p);
  for (const auto& [section, load] : s.product_loaders) load(s);
  const auto& surface = s.input.surface;
  ASSERT_EQ(surface.layers.size(), 2u);
  const drift::render::MaterialLayer& snow = surface.layers.back();
  EXPECT_EQ(snow.name, "snow");
  EXPECT_EQ(*snow.material.albedo, Eigen::Vector3f(0.8f, 0.85f, 0.9f));
  EXPECT_FLOAT_EQ(*snow.material.roughness, 0.3f);
  EXPECT_FLOAT_EQ(snow.mask(0, 0), 0.5f);
  EXPECT_FLOAT_EQ(snow.outside, 1.0f);
  EXPECT_TRUE(snow.flakes);
  EXPECT_TRUE(snow.buries_details);
  ASSERT_TRUE(snow.thickness.has_value());
  EXPECT_FLOAT_EQ(snow.thickness->scattering, 250.0f);
  ASSERT_EQ(s.input.height_changes.size(), 1u);
  ASSERT_EQ(surface.object_layers.size(), 1u);
  EXPECT_EQ(surface.object_layers[0].attribute, drift::terrain::products::kSnowCoverage);
  EXPECT_EQ(surface.object_layers[0].material.albedo, *snow.material.albedo);
}

TEST(SceneFile, BadLayerKeysAreErrors) {
  EXPECT_TRUE(refused_naming("[ripples]\nstrength = 1\n", "raster"));
  EXPECT_TRUE(
      refused_naming("[ripples]\nraster = \"r.tif\"\nfade_slope = [30, 20]\n", "fade_slope"));
  EXPECT_TRUE(refused_naming("[snow]\ncovr = \"c.tif\"\n", "snow.covr"));
}

TEST(SceneFile, CameraByLonLatStandsAboveTheGround) {
  // Mount St Helens' crater rim, looking at the summit area from the north.
  const std::string dem = std::string(DRIFT_SOURCE_DIR) + "/data/mount_st_helens_usgs_30m.dem";
  const fs::path p =
      write_scene("geo.toml", "[terrain]\nraster = \"" + dem +
                                  "\"\nexaggeration = 1.0\n"
                                  "[camera]\nfrom_lonlat = [-122.19, 46.215]\nfrom_height = 1.7\n"
                                  "to_lonlat = [-122.18, 46.19]\nfocal_length = 35\n");
  auto s = drift::pipeline::read_scene_file(p);
  drift::pipeline::load_scene_terrain(s);
  ASSERT_TRUE(s.input.camera.has_value());
  const auto& cam = *s.input.camera;
  // The heights under both ends, read back from the DEM, plus the heights asked for.
  const float ground_from =
      drift::render::sample_raster(s.input.terrain, cam.from.x(), cam.from.y(), NAN);
  const float ground_to =
      drift::render::sample_raster(s.input.terrain, cam.to.x(), cam.to.y(), NAN);
  EXPECT_NEAR(cam.from.z(), ground_from + 1.7, 1e-3);
  EXPECT_NEAR(cam.to.z(), ground_to, 1e-3);
  EXPECT_GT(ground_from, 1000.0f);  // on the mountain, not at sea level
  // 0.025 degrees of latitude apart: about 2.8 km north-south.
  EXPECT_NEAR(cam.from.y() - cam.to.y(), 2780.0, 60.0);
  ASSERT_TRUE(cam.focal_length_mm.has_value());
  EXPECT_DOUBLE_EQ(*cam.focal_length_mm, 35.0);
}

TEST(SceneFile, CameraOffTheTerrainOrHalfGivenIsAnError) {
  const std::string dem = std::string(DRIFT_SOURCE_DIR) + "/data/mount_st_helens_usgs_30m.dem";
  const fs::path p =
      write_scene("off.toml", "[terrain]\nraster = \"" + dem +
                                  "\"\n[camera]\nfrom_lonlat = [10.0, 46.2]\nto = [0, 0, 0]\n");
  auto s = drift::pipeline::read_scene_file(p);
  try {
    drift::pipeline::load_scene_terrain(s);
    ADD_FAILURE() << "a camera off the terrain must be an error";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("from_lonlat"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(refused_naming("[camera]\nfrom = [0, 0, 0]\n", "to_lonlat"));
  EXPECT_TRUE(
      refused_naming("[camera]\nfrom = [0, 0, 0]\nfrom_lonlat = [1, 2]\nto = [1, 1, 1]\n", "both"));
  EXPECT_TRUE(
      refused_naming("[camera]\nfrom = [0, 0, 0]\nto = [1, 1, 1]\nf_number = 2\n", "focal_length"));
}

TEST(SceneFile, SunFromDateTimeStandsOverTheDem) {
  // Mount St Helens (UTM zone 10, central meridian 123 W) on 2024-06-21 at
  // 13:00 PDT: NOAA's position over the DEM's centre, its azimuth turned to
  // grid north by the meridian convergence, about (lon + 123) sin(lat).
  const std::string dem = std::string(DRIFT_SOURCE_DIR) + "/data/mount_st_helens_usgs_30m.dem";
  const fs::path p = write_scene("sun.toml", "[terrain]\nraster = \"" + dem +
                                                 "\"\n[sun]\ndate = \"2024-06-21\"\n"
                                                 "time = \"13:00\"\ntimezone = \"-07:00\"\n");
  auto s = drift::pipeline::read_scene_file(p);
  drift::pipeline::load_scene_terrain(s);
  const auto& g = s.input.terrain.geo();
  const auto lonlat =
      drift::terrain::centre_lonlat(g, s.input.terrain.width(), s.input.terrain.height());
  const auto sun = drift::render::solar_position(
      drift::render::parse_local_time("2024-06-21", "13:00", "-07:00"), lonlat[1], lonlat[0]);
  EXPECT_DOUBLE_EQ(s.input.sun.elevation_deg, sun.elevation_deg);
  EXPECT_GT(sun.elevation_deg, 60.0);  // early afternoon at midsummer, 46 N
  const double convergence = (lonlat[0] + 123.0) * std::sin(lonlat[1] * M_PI / 180.0);
  EXPECT_NEAR(s.input.sun.azimuth_deg, sun.azimuth_deg - convergence, 0.02);
  // Both ways at once, or half a date, are errors.
  EXPECT_TRUE(
      refused_naming("[sun]\ndate = \"2024-06-21\"\ntime = \"13:00\"\nazimuth = 100\n", "both"));
  EXPECT_TRUE(refused_naming("[sun]\ndate = \"2024-06-21\"\n", "time"));
  EXPECT_NE(error_of(std::string(kTerrain) + "[sun]\ndate = \"2024-13-45\"\ntime = \"13:00\"\n"),
            "");
}

TEST(RenderCommand, SunTimeOverridesTheScenesSun) {
  // --sun-time puts the sun exactly where [sun] date/time would: the same
  // pixels; at night the frame is dark; a malformed time is a usage error.
  const std::string dem = std::string(DRIFT_SOURCE_DIR) + "/data/mount_st_helens_usgs_30m.dem";
  const std::string common = "[terrain]\nraster = \"" + dem + "\"\n[render]\nspp = 2\n";
  const fs::path by_date =
      write_scene("date.toml", common +
                                   "[sun]\ndate = \"2024-06-21\"\ntime = \"19:30\"\n"
                                   "timezone = \"-07:00\"\n");
  const fs::path by_angle =
      write_scene("angle.toml", common + "[sun]\nazimuth = 100\nelevation = 30\n");
  const fs::path dir = by_date.parent_path();
  auto render = [&](const fs::path& scene, const std::string& extra, const std::string& out) {
    const std::string cmd = std::string(DRIFT_EXECUTABLE) + " render " + scene.string() +
                            " --size 32x18 -o " + (dir / out).string() + " " + extra +
                            " 2>/dev/null >/dev/null";
    return WEXITSTATUS(std::system(cmd.c_str()));
  };
  ASSERT_EQ(render(by_date, "", "date.exr"), 0);
  ASSERT_EQ(render(by_angle, "--sun-time '2024-06-21 19:30 -07:00'", "cli.exr"), 0);
  ASSERT_EQ(render(by_angle, "--sun-time '2024-06-21 23:30 -07:00'", "night.exr"), 0);
  const auto date = drift::render::read_image(dir / "date.exr");
  const auto cli = drift::render::read_image(dir / "cli.exr");
  const auto night = drift::render::read_image(dir / "night.exr");
  EXPECT_EQ(date.pixels, cli.pixels);
  auto mean_red = [](const drift::render::Image& img) {
    double sum = 0.0;
    for (std::size_t i = 0; i < img.pixels.size(); i += img.channels.size()) sum += img.pixels[i];
    return sum / (img.pixels.size() / img.channels.size());
  };
  EXPECT_LT(mean_red(night), 0.2 * mean_red(cli));
  EXPECT_EQ(render(by_angle, "--sun-time '2024-06-21'", "bad.exr"), 2);
  EXPECT_EQ(render(by_angle, "--sun-time '2024-06-21 25:00'", "bad.exr"), 2);
  EXPECT_FALSE(fs::exists(dir / "bad.exr"));
}

TEST(SceneFile, ReadsMaterialRulesAndLayers) {
  const fs::path p = terrain_scene("materials.toml",
                                   "material = \"rock\"\nwetness = 0.2\n"
                                   "[[terrain.rule]]\nmaterial = \"grass\"\naltitude_max = 2400\n"
                                   "altitude_blend = 200\nslope_max = 30\n"
                                   "[[terrain.rule]]\ncolor = [0.5, 0.4, 0.3]\nslope_min = 40\n"
                                   "opacity = 0.5\n"
                                   "[[terrain.layer]]\nmask = \"wet.tif\"\nwetness = 1\n"
                                   "name = \"puddles\"\n"
                                   "[[terrain.layer]]\nmask = \"drift.tif\"\nmaterial = \"snow\"\n"
                                   "[[terrain.layer]]\nmask = \"film.tif\"\nmaterial = \"snow\"\n"
                                   "flakes = false\n");
  const auto s = drift::pipeline::read_scene_file(p);
  const auto& surface = s.input.surface;
  EXPECT_EQ(surface.ground.albedo, drift::render::material_preset("rock")->albedo);
  EXPECT_FLOAT_EQ(surface.ground.wetness, 0.2f);
  ASSERT_EQ(surface.rules.size(), 2u);
  EXPECT_EQ(*surface.rules[0].material.albedo, drift::render::material_preset("grass")->albedo);
  EXPECT_FLOAT_EQ(surface.rules[0].altitude.hi, 2400.0f);
  EXPECT_FLOAT_EQ(surface.rules[0].altitude.band, 200.0f);
  EXPECT_TRUE(std::isinf(surface.rules[0].altitude.lo));
  EXPECT_FLOAT_EQ(surface.rules[0].slope.hi, 30.0f);
  EXPECT_FLOAT_EQ(surface.rules[0].slope.band, 5.0f);  // the default band
  EXPECT_FALSE(surface.rules[1].material.roughness.has_value());
  EXPECT_FLOAT_EQ(surface.rules[1].opacity, 0.5f);
  ASSERT_EQ(surface.layers.size(), 3u);
  EXPECT_FLOAT_EQ(*surface.layers[0].material.wetness, 1.0f);
  // Snow placed by a mask shows as flakes unless told otherwise.
  EXPECT_FALSE(surface.layers[0].flakes);
  EXPECT_TRUE(surface.layers[1].flakes);
  EXPECT_FALSE(surface.layers[2].flakes);
  ASSERT_EQ(s.layer_masks.size(), 3u);
  EXPECT_EQ(s.layer_masks[0], p.parent_path() / "wet.tif");
  // Coverage channels: `name`, else the preset's name, else the fields the
  // entry sets (never its index: the name is the matte's in a compositor).
  EXPECT_EQ(surface.ground_name, "rock");
  EXPECT_EQ(surface.rules[0].name, "grass");
  EXPECT_EQ(surface.rules[1].name, "color");
  EXPECT_EQ(surface.layers[0].name, "puddles");
  EXPECT_TRUE(
      refused_naming("[[terrain.rule]]\nwetness = 1\nname = \"a b\"\n", "terrain.rule.name"));
}

TEST(SceneFile, BadMaterialKeysNameKeyAndFile) {
  const std::string t = kTerrain;
  const std::string preset = error_of(t + "[[terrain.rule]]\nmaterial = \"lava\"\n");
  EXPECT_NE(preset.find("'terrain.rule.material' is 'lava'"), std::string::npos) << preset;
  EXPECT_NE(preset.find("rock, dark_rock, scree"), std::string::npos) << preset;
  EXPECT_NE(preset.find("s.toml:4"), std::string::npos) << preset;
  EXPECT_TRUE(refused_naming("material = \"lava\"\n", "'terrain.material'"));
  EXPECT_TRUE(refused_naming("[[terrain.rule]]\nmaterial = \"sand\"\nslop_min = 3\n",
                             "terrain.rule.slop_min"));
  EXPECT_TRUE(
      refused_naming("[[terrain.rule]]\nmaterial = \"sand\"\nslope_min = 30\nslope_max = 20\n",
                     "terrain.rule.slope_max"));
  EXPECT_TRUE(refused_naming("[[terrain.rule]]\nmaterial = \"sand\"\nslope_max = 95\n",
                             "terrain.rule.slope_max' is 95"));
  EXPECT_TRUE(refused_naming("[[terrain.layer]]\nmask = \"m.tif\"\nwetness = 1.5\n",
                             "terrain.layer.wetness' is 1.5"));
  EXPECT_TRUE(refused_naming("[[terrain.layer]]\nmaterial = \"mud\"\n", "needs 'mask'"));
  const std::string empty = error_of(t + "[[terrain.rule]]\naltitude_min = 100\n");
  EXPECT_NE(empty.find("sets no material"), std::string::npos) << empty;
  EXPECT_NE(empty.find("s.toml"), std::string::npos) << empty;
  EXPECT_TRUE(refused_naming("rule = 3\n", "[[terrain.rule]]"));
}

TEST(SceneFile, CloudsAreReadAndChecked) {
  // No [clouds]: none (the default scenes stay clear and their bits unchanged).
  const fs::path clear = terrain_scene("clear.toml", "");
  EXPECT_FALSE(drift::pipeline::read_scene_file(clear).input.clouds.enabled);
  const fs::path p =
      terrain_scene("clouds.toml",
                    "[clouds]\ncoverage = 0.3\ndensity = 20\naltitude = 5200\nthickness = "
                    "600\nscale = 3000\nseed = 9\n");
  const drift::render::CloudOptions c = drift::pipeline::read_scene_file(p).input.clouds;
  EXPECT_TRUE(c.enabled);
  EXPECT_DOUBLE_EQ(c.coverage, 0.3);
  EXPECT_DOUBLE_EQ(c.density, 20.0);
  EXPECT_DOUBLE_EQ(c.altitude, 5200.0);
  EXPECT_DOUBLE_EQ(c.thickness, 600.0);
  EXPECT_DOUBLE_EQ(c.scale, 3000.0);
  EXPECT_EQ(c.seed, 9u);
  for (const char* bad : {"coverage = nan", "coverage = 1.5", "density = -1", "density = inf",
                          "altitude = 30000", "thickness = 0", "scale = 10", "seed = -3"}) {
    const std::string key =
        std::string("clouds.") + std::string(bad).substr(0, std::string(bad).find(' '));
    const std::string e = error_of(std::string(kTerrain) + "[clouds]\n" + bad + "\n");
    EXPECT_NE(e.find(key), std::string::npos) << bad << ": " << e;
    EXPECT_NE(e.find("s.toml"), std::string::npos) << e;
  }
  EXPECT_TRUE(refused_naming("[clouds]\ncover = 0.5\n", "cover"));
  const std::string simple =
      error_of(std::string(kTerrain) + "[sky]\nmodel = \"simple\"\n[clouds]\ncoverage = 0.5\n");
  EXPECT_NE(simple.find("physical sky"), std::string::npos) << simple;
}

// ${NAME} in a scene's strings: the file's [variables] give defaults, the
// caller's values (drift render --set) replace them, and a name neither gives
// is an error naming the key, the line and the way to give it.
TEST(SceneFile, VariablesNameProductsRelativeToAFolderTheCallerChooses) {
  const fs::path p = write_scene("vars.toml",
                                 "[variables]\nOUT = \"products\"\n"
                                 "[terrain]\nraster = \"${OUT}/dem.tif\"\n"
                                 "[output]\nfiles = [\"${OUT}/a.png\", \"b_${OUT}.exr\"]\n");
  const auto defaults = drift::pipeline::read_scene_file(p);
  EXPECT_EQ(defaults.terrain_raster, p.parent_path() / "products/dem.tif");
  ASSERT_EQ(defaults.outputs.size(), 2u);
  EXPECT_EQ(defaults.outputs[0], p.parent_path() / "products/a.png");
  EXPECT_EQ(defaults.outputs[1], p.parent_path() / "b_products.exr");
  const auto given = drift::pipeline::read_scene_file(p, {{"OUT", "/data/run 1"}});
  EXPECT_EQ(given.terrain_raster, fs::path("/data/run 1/dem.tif"));
  EXPECT_EQ(given.outputs[0], fs::path("/data/run 1/a.png"));
}

TEST(SceneFile, UnknownOrMalformedVariablesAreRefusedSayingHowToGiveThem) {
  const std::string unknown = error_of("[terrain]\nraster = \"${OUTT}/dem.tif\"\n");
  EXPECT_NE(unknown.find("s.toml:2: terrain.raster: unknown variable ${OUTT}"), std::string::npos)
      << unknown;
  EXPECT_NE(unknown.find("--set OUTT=VALUE"), std::string::npos) << unknown;
  const std::string open = error_of("[terrain]\nraster = \"${OUT/dem.tif\"\n");
  EXPECT_NE(open.find("without its closing"), std::string::npos) << open;
  const std::string number = error_of("[variables]\nOUT = 3\n" + std::string(kTerrain));
  EXPECT_NE(number.find("[variables] OUT: give a string"), std::string::npos) << number;
  const std::string empty_name = error_of("[terrain]\nraster = \"${}/dem.tif\"\n");
  EXPECT_NE(empty_name.find("unknown variable ${}"), std::string::npos) << empty_name;
  // A lone '$' is no variable.
  EXPECT_EQ(error_of("[terrain]\nraster = \"$dem.tif\"\n"), "");
}
