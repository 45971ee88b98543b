// The EXR's layers by the compositing conventions (docs/rendering.md, "EXR
// layers"): Z, N, P relative to the header's worldOrigin, OpenEXR's
// worldToCamera and worldToNDC, and Cryptomatte mattes read back by a
// decoder written here from the specification alone.
#include <gtest/gtest.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <regex>

#include "render/cryptomatte.h"
#include "render/image_io.h"
#include "render/renderer.h"
#include "render/terrain_scene.h"
#include "tests/test_files.h"
#include "tests/utm_fixture.h"

using namespace drift::render;

namespace {

// A tilted plane at UTM-sized coordinates, where float32 keeps only
// 0.25-0.5 m: z = 1500 + 0.2 (x - 741000) + 0.1 (y - 4029000).
constexpr double kWest = 741000.0, kNorth = 4029640.0;
double plane(double x, double y) { return 1500.0 + 0.2 * (x - 741000.0) + 0.1 * (y - 4029000.0); }

SceneInput utm_plane_scene() {
  SceneInput in;
  drift::terrain::GeoReference geo;
  geo.geotransform = {kWest, 10.0, 0.0, kNorth, 0.0, -10.0};
  in.terrain = drift::terrain::HeightField(64, 64, 0.0f, geo);
  for (int row = 0; row < 64; ++row)
    for (int col = 0; col < 64; ++col)
      in.terrain(col, row) =
          static_cast<float>(plane(kWest + (col + 0.5) * 10.0, kNorth - (row + 0.5) * 10.0));
  // Two classes meeting in a soft band, so pixels hold several IDs.
  in.surface.ground_name = "rock";
  MaterialRule grass;
  grass.name = "grass";
  grass.material.albedo = Eigen::Vector3f(0.1f, 0.2f, 0.05f);
  grass.altitude = {-1e9f, 1620.0f, 40.0f};
  in.surface.rules.push_back(grass);
  in.sky.model = SkyModel::Simple;
  return in;
}

// A 60 m square roof standing over the plane near its centre, named "hut".
void add_roof(SceneInput& in, const Eigen::Vector3d& centre) {
  drift::terrain::PlacedMesh roof;
  roof.position = centre;
  for (auto [x, y] : {std::pair{-30.f, -30.f}, {30.f, -30.f}, {30.f, 30.f}, {-30.f, 30.f}})
    roof.mesh.positions.emplace_back(x, y, 25.0f);
  roof.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  roof.material = "snow";
  in.meshes.push_back(roof);
  in.object_names = {"hut"};
}

using drift::testing::utm53_wkt;

const std::string& text(const Image& im, const std::string& name) {
  for (const auto& [k, v] : im.header_texts)
    if (k == name) return v;
  static const std::string none;
  ADD_FAILURE() << "no header attribute " << name;
  return none;
}

// A Cryptomatte decoder after the specification (1.1.0): finds the type's
// key by its name attribute, reads the manifest (name -> 8 hex digits of the
// float bits) and the <type>NN.RGBA pairs.
struct Cryptomatte {
  std::map<std::uint32_t, std::string> names;  // float bits -> name
  std::vector<int> channels;                   // ID, coverage, ID, coverage, ...

  Cryptomatte(const Image& im, const std::string& type) {
    std::string key;
    const std::regex name_key("cryptomatte/([0-9a-f]{1,7})/name");
    for (const auto& [k, v] : im.header_texts) {
      std::smatch m;
      if (v == type && std::regex_match(k, m, name_key)) key = m[1];
    }
    EXPECT_FALSE(key.empty()) << type;
    EXPECT_EQ(text(im, "cryptomatte/" + key + "/hash"), "MurmurHash3_32");
    EXPECT_EQ(text(im, "cryptomatte/" + key + "/conversion"), "uint32_to_float32");
    const std::string manifest = text(im, "cryptomatte/" + key + "/manifest");
    const std::regex entry("\"([^\"]+)\":\"([0-9a-f]{8})\"");
    for (auto it = std::sregex_iterator(manifest.begin(), manifest.end(), entry);
         it != std::sregex_iterator(); ++it)
      names[static_cast<std::uint32_t>(std::stoul((*it)[2], nullptr, 16))] = (*it)[1];
    for (int layer = 0;; ++layer) {
      char base[64];
      std::snprintf(base, sizeof base, "%s%02d", type.c_str(), layer);
      const int r = im.channel_index(std::string(base) + ".R");
      if (r < 0) break;  // layers 00, 01, ... until one is missing
      for (const char* c : {".R", ".G", ".B", ".A"})
        channels.push_back(im.channel_index(std::string(base) + c));
    }
    EXPECT_GE(channels.size(), 4u) << type;
  }

  // The pixel's coverage by name ("" for ID 0, the sky).
  std::map<std::string, float> decode(const Image& im, int x, int y) const {
    std::map<std::string, float> out;
    for (std::size_t i = 0; i + 1 < channels.size(); i += 2) {
      const float id = im.at(x, y, channels[i]), coverage = im.at(x, y, channels[i + 1]);
      if (coverage == 0.0f) continue;
      std::uint32_t bits;
      std::memcpy(&bits, &id, 4);
      const auto found = names.find(bits);
      if (id == 0.0f) {
        out[""] += coverage;
      } else if (found != names.end()) {
        out[found->second] += coverage;
      } else {
        ADD_FAILURE() << "ID " << std::hex << bits << " is not in the manifest";
      }
    }
    return out;
  }
};

// Row vector p (x, y, z, 1) times an Imath row-major 4x4: (x', y', z', w').
Eigen::Vector4d times(const std::array<float, 16>& m, const Eigen::Vector3d& p) {
  Eigen::Vector4d out;
  for (int j = 0; j < 4; ++j)
    out[j] = p.x() * m[j] + p.y() * m[4 + j] + p.z() * m[8 + j] + m[12 + j];
  return out;
}

const std::array<float, 16>& matrix(const Image& im, const std::string& name) {
  for (const auto& [k, v] : im.header_matrices)
    if (k == name) return v;
  static const std::array<float, 16> none{};
  ADD_FAILURE() << "no matrix " << name;
  return none;
}

}  // namespace

TEST(Cryptomatte, HashesAndIdsFollowTheSpecification) {
  // MurmurHash3_x86_32, seed 0: the reference implementation's values.
  EXPECT_EQ(murmur3_32(""), 0u);
  EXPECT_EQ(murmur3_32("hello"), 0x248bfa47u);
  EXPECT_EQ(murmur3_32("The quick brown fox jumps over the lazy dog"), 0x2e4ff723u);
  // The specification's manifest examples (name -> float bits).
  EXPECT_EQ(cryptomatte_hex(cryptomatte_id("bunny")), "13851a76");
  EXPECT_EQ(cryptomatte_hex(cryptomatte_id("default")), "42c9679f");
  EXPECT_EQ(cryptomatte_hex(cryptomatte_id("bunny_porcelain_mat")), "b24b26d4");
  // Every ID is a finite, normal float (the exponent clamped to [1, 254]).
  for (int i = 0; i < 20000; ++i) {
    const float id = cryptomatte_id("name" + std::to_string(i));
    ASSERT_TRUE(std::isnormal(id)) << i;
  }
}

// A pixel's (ID, coverage) pairs: heaviest first, ties in name order (the
// empty ID last among equals), as a stable sort by coverage gives them;
// for few names (rank_coverage's insertion sort) and for many (its
// std::stable_sort), with many ties.
TEST(Cryptomatte, RanksByCoverageTiesInNameOrder) {
  for (const std::size_t n : {std::size_t{7}, std::size_t{45}}) {
    CryptomatteLayer layer;
    layer.type = "CryptoMaterial";
    std::vector<float> ids, weights;
    for (std::size_t i = 0; i < n; ++i) {
      layer.names.push_back("m" + std::to_string(i));
      ids.push_back(cryptomatte_id(layer.names.back()));
      weights.push_back(static_cast<float>((i * 7) % 4) * 0.05f);  // four values, many ties
    }
    const float empty = 0.05f;  // ties with names too
    layer.ranks = ranks_for(n);
    std::vector<float> out(2 * static_cast<std::size_t>(layer.ranks), -1.0f);
    rank_coverage(layer, ids, weights.data(), empty, out.data());
    std::vector<std::size_t> expected(n + 1);
    std::iota(expected.begin(), expected.end(), std::size_t{0});
    const auto w = [&](std::size_t i) { return i == n ? empty : weights[i]; };
    std::stable_sort(expected.begin(), expected.end(),
                     [&](std::size_t a, std::size_t b) { return w(a) > w(b); });
    for (int r = 0; r < layer.ranks; ++r) {
      const std::size_t k = static_cast<std::size_t>(r);
      const bool shown = k < expected.size() && w(expected[k]) > 0.0f;
      const float id = !shown || expected[k] == n ? 0.0f : ids[expected[k]];
      EXPECT_EQ(out[2 * k], id) << n << " names, rank " << r;
      EXPECT_EQ(out[2 * k + 1], shown ? w(expected[k]) : 0.0f) << n << " names, rank " << r;
    }
  }
}

TEST(ExrLayers, ConventionalChannelsHeaderAndMattesReadBack) {
  SceneInput in = utm_plane_scene();
  in.terrain.geo().crs_wkt = utm53_wkt();
  const TerrainScene probe(in);
  add_roof(in, probe.origin() + Eigen::Vector3d(40.0, 60.0, 0.0) +
                   Eigen::Vector3d(0, 0,
                                   plane(probe.origin().x() + 40, probe.origin().y() + 60) -
                                       probe.origin().z()));
  const TerrainScene scene(in);
  Camera camera;
  camera.from = scene.origin() + Eigen::Vector3d(-150.0, -250.0, 300.0);
  camera.to = scene.origin() + Eigen::Vector3d(0.0, 40.0, 0.0);
  camera.vertical_fov_deg = 50.0;
  RenderSettings rs;
  rs.width = 64, rs.height = 48, rs.samples_per_pixel = 8, rs.max_depth = 1;
  const auto dir = drift::testing::test_dir("exr_layers");
  write_exr(render_image(scene, in, camera, rs), dir / "frame.exr");
  const Image im = read_image(dir / "frame.exr");

  for (const char* c : {"Z", "N.X", "N.Y", "N.Z", "albedo.R", "P.X", "P.Y", "P.Z", "coverage.rock",
                        "coverage.grass", "mask.sky"})
    EXPECT_GE(im.channel_index(c), 0) << c;
  EXPECT_LT(im.channel_index("depth"), 0);
  EXPECT_EQ(text(im, "crsWKT"), in.terrain.geo().crs_wkt);
  ASSERT_EQ(im.header_vectors.size(), 1u);
  EXPECT_EQ(im.header_vectors[0].first, "worldOrigin");
  const auto& o = im.header_vectors[0].second;
  const Eigen::Vector3d origin(o[0], o[1], o[2]);
  EXPECT_EQ(origin, scene.origin().array().round().matrix()) << "whole metres, exact as float";

  const Cryptomatte material(im, "CryptoMaterial"), object(im, "CryptoObject");
  const std::array<float, 16>& to_camera = matrix(im, "worldToCamera");
  const std::array<float, 16>& to_ndc = matrix(im, "worldToNDC");
  const int px = im.channel_index("P.X"), z = im.channel_index("Z");
  int ground_pixels = 0, roof_pixels = 0, mixed_material = 0;
  double worst_height = 0.0, worst_ndc = 0.0, worst_z = 0.0;
  for (int y = 0; y < im.height; ++y) {
    for (int x = 0; x < im.width; ++x) {
      // Both mattes' coverages sum to 1 (the sky is ID 0).
      for (const Cryptomatte* c : {&material, &object}) {
        float sum = 0.0f;
        for (const auto& [name, coverage] : c->decode(im, x, y)) sum += coverage;
        EXPECT_NEAR(sum, 1.0f, 1e-5f) << x << "," << y;
      }
      const auto objects = object.decode(im, x, y);
      const auto materials = material.decode(im, x, y);
      if (materials.size() > 1) ++mixed_material;
      if (objects.count("hut") && objects.at("hut") == 1.0f) {
        ++roof_pixels;
        EXPECT_FLOAT_EQ(materials.at("snow"), 1.0f) << "the roof's material is its preset";
      }
      if (!(objects.count("terrain") && objects.at("terrain") == 1.0f)) continue;
      ++ground_pixels;
      // P: on the DEM's surface to a centimetre once the origin is added
      // back in double (float32 of the CRS coordinates would miss by 0.25 m).
      const Eigen::Vector3d p(im.at(x, y, px), im.at(x, y, px + 1), im.at(x, y, px + 2));
      const Eigen::Vector3d crs = p + origin;
      // Well inside the DEM (beyond it the ground goes on as the surround,
      // render/surround.h, not on the plane; a pixel is ~12 m wide there).
      if (crs.x() < kWest + 40 || crs.x() > kWest + 600 || crs.y() > kNorth - 40 ||
          crs.y() < kNorth - 600)
        continue;
      worst_height = std::max(worst_height, std::abs(crs.z() - plane(crs.x(), crs.y())));

      // P through worldToNDC lands in its pixel (the mean of its samples);
      // its camera-space z is the Z channel.
      const Eigen::Vector4d ndc = times(to_ndc, p);
      worst_ndc = std::max({worst_ndc, std::abs(ndc.x() / ndc.w() * im.width - (x + 0.5)),
                            std::abs(ndc.y() / ndc.w() * im.height - (y + 0.5))});
      const Eigen::Vector4d cam = times(to_camera, p);
      worst_z = std::max(worst_z, std::abs(cam.z() - im.at(x, y, z)) / im.at(x, y, z));
    }
  }
  std::printf(
      "P off the surface: at most %.2g m over %d ground pixels; P to its pixel %.3f px; "
      "Z against P's camera z %.2g\n",
      worst_height, ground_pixels, worst_ndc, worst_z);
  EXPECT_GT(ground_pixels, 800);
  EXPECT_GT(roof_pixels, 5);
  EXPECT_GT(mixed_material, 10) << "the soft band between rock and grass";
  EXPECT_LT(worst_height, 0.01) << "metres off the DEM's surface";
  EXPECT_LT(worst_ndc, 0.3) << "pixels between P's projection and its pixel";
  EXPECT_LT(worst_z, 1e-4) << "relative difference of Z and P's camera z";
}

TEST(ExrLayers, SkyPixelsAreIdZeroAndFar) {
  // Looking at the horizon: sky pixels are ID 0 with coverage 1 and Z far.
  SceneInput in = utm_plane_scene();
  const TerrainScene scene(in);
  Camera camera;
  camera.from = scene.origin() + Eigen::Vector3d(0.0, 0.0, 400.0);
  camera.to = scene.origin() + Eigen::Vector3d(0.0, 1000.0, 400.0);
  camera.vertical_fov_deg = 30.0;
  RenderSettings rs;
  rs.width = 16, rs.height = 8, rs.samples_per_pixel = 2, rs.max_depth = 1;
  const Image im = render_image(scene, in, camera, rs);
  const Cryptomatte object(im, "CryptoObject");
  const auto top = object.decode(im, 8, 0);
  ASSERT_EQ(top.size(), 1u);
  EXPECT_EQ(top.begin()->first, "");
  EXPECT_EQ(im.at(8, 0, im.channel_index("Z")), 1e10f);
  EXPECT_EQ(im.at(8, 0, im.channel_index("mask.sky")), 1.0f);
}
