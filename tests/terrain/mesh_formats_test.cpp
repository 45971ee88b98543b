// Meshes through Assimp and the glTF/STL/FBX writers (issue 37 item 4): a GLB
// read back by Assimp gives the same vertices and bounding box; the file itself
// holds glTF's y-up frame (decoded here by hand, not by the reader under test);
// FBX's units and axes come from its header; STL reads binary and ASCII; a
// malformed glTF, a FIFO and a buffer naming a device are refused, naming the file.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <regex>
#include <string>

#include "terrain/error.h"
#include "terrain/height_mesh.h"
#include "terrain/mesh_io.h"
#include "tests/test_files.h"

using namespace drift::terrain;
using drift::testing::put;
using drift::testing::slurp;
using drift::testing::test_dir;
namespace fs = std::filesystem;

namespace {

// A tetrahedron off the origin with no symmetry that could hide a swapped or
// negated axis, one attribute, and a CRS origin at UTM magnitude.
Mesh tetra() {
  Mesh m;
  m.positions = {
      {1.5f, -2.25f, 0.125f}, {4.0f, -2.0f, 0.5f}, {2.0f, 3.75f, 0.25f}, {2.5f, 0.5f, 6.0f}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};  // outward, counter-clockwise
  m.vertex_attributes = {{"snow_coverage", {0.0f, 0.25f, 0.5f, 1.0f}}};
  m.origin = {746633.0, 4032753.0, 12.5};
  return m;
}

void expect_same_vertices(const Mesh& a, const Mesh& b, float tol) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (std::size_t i = 0; i < a.positions.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(a.positions[i][k], b.positions[i][k], tol) << "vertex " << i << " axis " << k;
}

// The same triangles at the same corners (for formats that store a vertex per
// corner, as FBX through Assimp and STL do). `scale` multiplies `a`.
void expect_same_corners(const Mesh& a, const Mesh& b, float tol, float scale = 1.0f) {
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (std::size_t t = 0; t < a.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3f p = scale * a.positions[static_cast<std::size_t>(a.triangles[t][c])];
      const Eigen::Vector3f q = b.positions[static_cast<std::size_t>(b.triangles[t][c])];
      EXPECT_LT((p - q).norm(), tol * scale) << "triangle " << t << " corner " << c;
    }
}

Eigen::AlignedBox3f box(const Mesh& m) {
  Eigen::AlignedBox3f b;
  for (const auto& p : m.positions) b.extend(p);
  return b;
}

// The JSON and BIN chunks of a GLB, decoded by hand (glTF 2.0, 4.4).
struct Glb {
  std::string json, bin;
};
Glb split_glb(const std::string& bytes) {
  auto u32 = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  Glb g;
  EXPECT_EQ(u32(0), 0x46546C67u);  // "glTF"
  EXPECT_EQ(u32(4), 2u);
  EXPECT_EQ(u32(8), bytes.size());
  const std::uint32_t json_len = u32(12);
  EXPECT_EQ(u32(16), 0x4E4F534Au);
  g.json = bytes.substr(20, json_len);
  const std::size_t bin_at = 20 + json_len;
  EXPECT_EQ(u32(bin_at + 4), 0x004E4942u);
  g.bin = bytes.substr(bin_at + 8, u32(bin_at));
  return g;
}

}  // namespace

TEST(MeshFormats, GlbRoundTripThroughAssimpKeepsVerticesAndBox) {
  const fs::path d = test_dir("mesh_formats");
  const Mesh m = tetra();
  write_mesh(m, d / "tetra.glb");
  const Mesh back = read_mesh(d / "tetra.glb");  // Assimp's glTF2 importer
  expect_same_vertices(m, back, 1e-6f);
  ASSERT_EQ(back.triangles.size(), m.triangles.size());
  for (std::size_t t = 0; t < m.triangles.size(); ++t) EXPECT_EQ(back.triangles[t], m.triangles[t]);
  EXPECT_TRUE(box(back).isApprox(box(m), 1e-6f));
  // Normals come back unit length and pointing out of the tetrahedron, as written.
  ASSERT_EQ(back.normals.size(), back.positions.size());
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const auto& p : m.positions) centre += p / 4;
  for (std::size_t v = 0; v < back.normals.size(); ++v) {
    EXPECT_NEAR(back.normals[v].norm(), 1.0f, 1e-5f);
    EXPECT_GT(back.normals[v].dot(back.positions[v] - centre), 0.0f) << "vertex " << v;
  }
  // The .gltf form (buffer as a data URI) reads back the same.
  write_mesh(m, d / "tetra.gltf");
  expect_same_vertices(m, read_mesh(d / "tetra.gltf"), 1e-6f);
}

TEST(MeshFormats, GlbHoldsGltfsYUpFrameInMetres) {
  const fs::path d = test_dir("mesh_formats");
  const Mesh m = tetra();
  write_gltf(m, d / "tetra.glb");
  const Glb g = split_glb(slurp(d / "tetra.glb"));
  // drift (x east, y north, z up) is stored as glTF (x, z, -y): height is glTF's y.
  std::smatch mm;
  const std::regex bounds(
      R"re("min":\[([-0-9.e]+),([-0-9.e]+),([-0-9.e]+)\],"max":\[([-0-9.e]+),([-0-9.e]+),([-0-9.e]+)\])re");
  ASSERT_TRUE(std::regex_search(g.json, mm, bounds)) << g.json;
  const Eigen::AlignedBox3f b = box(m);
  EXPECT_FLOAT_EQ(std::stof(mm[1]), b.min().x());
  EXPECT_FLOAT_EQ(std::stof(mm[2]), b.min().z());   // glTF y = drift z
  EXPECT_FLOAT_EQ(std::stof(mm[3]), -b.max().y());  // glTF z = -drift y
  EXPECT_FLOAT_EQ(std::stof(mm[5]), b.max().z());
  EXPECT_FLOAT_EQ(std::stof(mm[6]), -b.min().y());
  // The first vertex as stored (the POSITION view starts the buffer).
  float first[3];
  std::memcpy(first, g.bin.data(), sizeof first);
  EXPECT_EQ(first[0], m.positions[0].x());
  EXPECT_EQ(first[1], m.positions[0].z());
  EXPECT_EQ(first[2], -m.positions[0].y());
  // The attribute is a custom vertex attribute, and the CRS origin is kept.
  EXPECT_NE(g.json.find("\"_SNOW_COVERAGE\":"), std::string::npos) << g.json;
  EXPECT_NE(g.json.find("\"drift_origin\":[746633,4032753,12.5]"), std::string::npos) << g.json;
  EXPECT_NE(g.json.find("\"NORMAL\":"), std::string::npos);
}

TEST(MeshFormats, GltfAndFbxTakeTheirOwnUpAxisAndUnits) {
  const fs::path d = test_dir("mesh_formats");
  const Mesh m = tetra();
  // A glTF object read with y_up = false is taken as stored: z up in the file
  // is then drift's -y, which is what a y-up default would undo.
  write_mesh(m, d / "tetra.glb");
  const Mesh as_stored = read_mesh(d / "tetra.glb", UpAxis::Z);
  EXPECT_FLOAT_EQ(as_stored.positions[3].y(), m.positions[3].z());
  // FBX: Assimp's ASCII writer, y up in centimetres (UnitScaleFactor 1).
  write_mesh(m, d / "tetra.fbx");
  expect_same_corners(m, read_mesh(d / "tetra.fbx"), 1e-5f);
  // The same file declaring metres (UnitScaleFactor 100 cm a unit) is 100 times larger.
  std::string text = slurp(d / "tetra.fbx");
  const std::string unit = "\"UnitScaleFactor\", \"double\", \"Number\", \"\", 1";
  const auto at = text.find(unit);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, unit.size(), unit + "00");
  put(d / "metres.fbx", text);
  expect_same_corners(m, read_mesh(d / "metres.fbx"), 1e-5f, 100.0f);
}

TEST(MeshFormats, StlReadsBinaryAndAscii) {
  const fs::path d = test_dir("mesh_formats");
  const Mesh m = tetra();
  write_stl(m, d / "tetra.stl");
  EXPECT_EQ(fs::file_size(d / "tetra.stl"), 84u + 50u * m.triangles.size());
  const Mesh bin = read_mesh(d / "tetra.stl");
  // STL repeats each corner per facet: 12 vertices, z up and metres as stored.
  EXPECT_TRUE(box(bin).isApprox(box(m), 1e-6f));
  expect_same_corners(m, bin, 1e-7f);
  put(d / "facet.stl",
      "solid one\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 2 0 0.5\n"
      "   vertex 0 3 1\n  endloop\n endfacet\nendsolid one\n");
  const Mesh ascii = read_mesh(d / "facet.stl");
  ASSERT_EQ(ascii.triangles.size(), 1u);
  EXPECT_EQ(ascii.positions[static_cast<std::size_t>(ascii.triangles[0][1])],
            Eigen::Vector3f(2, 0, 0.5f));
  EXPECT_EQ(ascii.positions[static_cast<std::size_t>(ascii.triangles[0][2])],
            Eigen::Vector3f(0, 3, 1));
}

TEST(MeshFormats, MalformedGltfIsRefusedNamingTheFile) {
  const fs::path d = test_dir("mesh_formats");
  auto refusal = [](const fs::path& p) -> std::string {
    try {
      read_mesh(p);
    } catch (const drift::Error& e) {
      return e.what();
    }
    return "";
  };
  put(d / "broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [ {\"primitives\": ");
  std::string why = refusal(d / "broken.gltf");
  EXPECT_NE(why.find((d / "broken.gltf").string()), std::string::npos) << why;
  // A GLB cut short inside its binary chunk.
  write_mesh(tetra(), d / "whole.glb");
  const std::string bytes = slurp(d / "whole.glb");
  put(d / "cut.glb", bytes.substr(0, bytes.size() - 40));
  why = refusal(d / "cut.glb");
  EXPECT_NE(why.find((d / "cut.glb").string()), std::string::npos) << why;
  // An accessor reading past its buffer.
  write_mesh(tetra(), d / "ok.gltf");
  std::string text = slurp(d / "ok.gltf");
  const auto count = text.find("\"count\":4");
  ASSERT_NE(count, std::string::npos);
  text.replace(count, 9, "\"count\":4000000");
  put(d / "overrun.gltf", text);
  why = refusal(d / "overrun.gltf");
  EXPECT_NE(why.find((d / "overrun.gltf").string()), std::string::npos) << why;
  // A missing file.
  EXPECT_NE(refusal(d / "no_such.glb").find("no_such.glb"), std::string::npos);
}

TEST(MeshFormats, EveryFileAssimpOpensPassesTheInputChecks) {
  const fs::path d = test_dir("mesh_formats");
  // A FIFO named as the mesh is refused before it is opened (it would block).
  ASSERT_EQ(mkfifo((d / "pipe.glb").c_str(), 0600), 0);
  EXPECT_THROW(read_mesh(d / "pipe.glb"), drift::Error);
  // A .gltf whose buffer is a link to a device: refused, not read forever.
  fs::create_symlink("/dev/zero", d / "zero.bin");
  write_mesh(tetra(), d / "ok.gltf");
  std::string text = slurp(d / "ok.gltf");
  const auto uri = text.find("\"uri\":\"");
  ASSERT_NE(uri, std::string::npos);
  const auto end = text.find('"', uri + 7);
  text.replace(uri, end + 1 - uri, "\"uri\":\"zero.bin\"");
  put(d / "device.gltf", text);
  try {
    read_mesh(d / "device.gltf");
    ADD_FAILURE() << "a buffer on /dev/zero was read";
  } catch (const drift::Error& e) {
    const std::string why = e.what();
    EXPECT_NE(why.find("device.gltf"), std::string::npos) << why;
    EXPECT_NE(why.find("zero.bin': it is a device"), std::string::npos) << why;
  }
}

TEST(MeshFormats, HeightFieldMeshIsCounterClockwiseFromAboveAndKeepsTheCrs) {
  // A 3 x 3 north-up grid at UTM magnitude, rising to the east.
  HeightField h(3, 3, 0.0f);
  h.geo().geotransform = {700000.0, 2.0, 0.0, 4000000.0, 0.0, -2.0};
  for (int r = 0; r < 3; ++r)
    for (int x = 0; x < 3; ++x) h(x, r) = 100.0f + static_cast<float>(x);
  h(2, 2) = NAN;  // the south-east square is left out
  const Mesh m = height_field_mesh(h, 1);
  EXPECT_EQ(m.triangles.size(), 6u);  // 3 squares of 2
  EXPECT_EQ(m.origin, Eigen::Vector3d(700001.0, 3999999.0, 0.0));
  for (const auto& t : m.triangles) {
    const Eigen::Vector3f n =
        (m.positions[static_cast<std::size_t>(t[1])] - m.positions[static_cast<std::size_t>(t[0])])
            .cross(m.positions[static_cast<std::size_t>(t[2])] -
                   m.positions[static_cast<std::size_t>(t[0])]);
    EXPECT_GT(n.z(), 0.0f);  // faces up
    EXPECT_LT(n.x(), 0.0f);  // a slope rising east faces west
  }
  EXPECT_EQ(m.positions[0], Eigen::Vector3f(0, 0, 100));
}

namespace {

// A GLB of `json` and `bin`, each chunk padded as write_gltf pads them.
std::string join_glb(std::string json, std::string bin) {
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin += '\0';
  auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  return u32(0x46546C67u) + u32(2) +
         u32(static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size())) +
         u32(static_cast<std::uint32_t>(json.size())) + u32(0x4E4F534Au) + json +
         u32(static_cast<std::uint32_t>(bin.size())) + u32(0x004E4942u) + bin;
}

std::string glb_refusal(const fs::path& p) {
  try {
    read_glb(p);
  } catch (const drift::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// drift's own GLB reader (issue 37; Assimp drops custom attributes,
// assimp#4830) gives back what the PLY path gives: the same positions,
// triangles, named attributes and origin bit for bit, normals to 1e-6.
TEST(MeshFormats, OwnGlbReadBackEqualsThePlyPath) {
  const fs::path d = test_dir("mesh_formats");
  Mesh m = tetra();
  m.vertex_attributes.push_back({"object", {0.0f, 0.0f, 1.0f, 1.0f}});
  m.normals = vertex_normals(m);
  write_mesh(m, d / "t.glb");
  write_mesh(m, d / "t.ply");
  const Mesh g = read_glb(d / "t.glb"), p = read_ply(d / "t.ply");
  ASSERT_EQ(g.positions.size(), p.positions.size());
  for (std::size_t v = 0; v < g.positions.size(); ++v) {
    EXPECT_EQ(g.positions[v], p.positions[v]) << "vertex " << v;
    EXPECT_LT((g.normals.at(v) - p.normals.at(v)).norm(), 1e-6f) << "normal " << v;
  }
  EXPECT_EQ(g.triangles, p.triangles);
  EXPECT_EQ(g.origin, p.origin);
  ASSERT_EQ(g.vertex_attributes.size(), 2u);
  EXPECT_EQ(g.vertex_attributes, p.vertex_attributes);
  // Assimp, by contrast, loses the attribute (why read_glb exists).
  EXPECT_EQ(read_mesh(d / "t.glb").attribute("snow_coverage"), nullptr);
}

// Malformed GLBs are refused naming the file and what is wrong, before
// anything is sized by a declared count: cut short, chunk lengths and
// offsets past the file, a huge count, a wrong component type, an index past
// the vertices, JSON that does not parse.
TEST(MeshFormats, MalformedGlbIsRefusedByTheOwnReader) {
  const fs::path d = test_dir("mesh_formats");
  write_mesh(tetra(), d / "whole.glb");
  const std::string bytes = slurp(d / "whole.glb");
  const Glb g = split_glb(bytes);
  auto expect = [&](const std::string& name, const std::string& file, const std::string& says) {
    put(d / name, file);
    const std::string why = glb_refusal(d / name);
    EXPECT_NE(why.find((d / name).string()), std::string::npos) << name << ": " << why;
    EXPECT_NE(why.find(says), std::string::npos) << name << ": " << why;
  };
  auto edit = [&](std::string json, const std::string& from, const std::string& to) {
    const auto at = json.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) json.replace(at, from.size(), to);
    return json;
  };
  expect("cut.glb", bytes.substr(0, bytes.size() - 40), "truncated?");
  expect("tiny.glb", bytes.substr(0, 10), "too short for GLB");
  // The BIN chunk declaring more bytes than the file holds (header length fixed up).
  std::string past = bytes;
  const std::uint32_t huge = 0x7fffff00u;
  std::memcpy(&past[20 + g.json.size()], &huge, 4);
  expect("chunk_past_end.glb", past, "past the file's end");
  // The first accessor (POSITION) declaring 2^31 vertices.
  expect("huge_count.glb", join_glb(edit(g.json, "\"count\":4", "\"count\":2147483648"), g.bin),
         "past its bufferView's 48 bytes");
  expect("too_many.glb", join_glb(edit(g.json, "\"count\":4", "\"count\":99999999999"), g.bin),
         "outside [1, 2147483648]");
  // A bufferView past buffer 0, and one at an offset beyond it.
  expect("view_past.glb", join_glb(edit(g.json, "\"byteLength\":48", "\"byteLength\":4800"), g.bin),
         "outside [1, ");
  expect("offset_past.glb",
         join_glb(edit(g.json, "\"byteOffset\":0,\"byteLength\":48",
                       "\"byteOffset\":200,\"byteLength\":48"),
                  g.bin),
         "reaches past buffer 0's");
  // POSITION as unsigned shorts; indices as floats.
  expect("component.glb",
         join_glb(edit(g.json, "\"componentType\":5126", "\"componentType\":5123"), g.bin),
         "componentType 5123, not one drift reads");
  std::string json = g.json;
  const auto last = json.rfind("\"componentType\":5125");
  ASSERT_NE(last, std::string::npos);
  json.replace(last, 20, "\"componentType\":5126");
  expect("float_indices.glb", join_glb(json, g.bin), "componentType 5126");
  // An index naming vertex 9 of 4.
  std::string bin = g.bin;
  const std::uint32_t nine = 9;
  std::memcpy(&bin[bin.size() - 4], &nine, 4);
  expect("index_past.glb", join_glb(g.json, bin), "names vertex 9 of 4");
  expect("broken_json.glb", join_glb(g.json.substr(0, g.json.size() / 2), g.bin), "does not parse");
  expect("deep_json.glb", join_glb(std::string(5000, '[') + std::string(5000, ']'), g.bin),
         "does not parse");
  EXPECT_NE(glb_refusal(d / "no_such.glb").find("no_such.glb"), std::string::npos);
}
