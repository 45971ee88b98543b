// PLY meshes: a write/read round trip keeps positions, attributes and the CRS
// origin; splitting by an attribute; malformed files are clear errors. OBJ
// meshes: what tinyobjloader would misread, block on or take quadratic time over
// is refused or avoided.
#include "terrain/mesh_io.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "terrain/error.h"

using namespace drift::terrain;
namespace fs = std::filesystem;

namespace {

// Two triangles (object 0) and one (object 1).
Mesh two_objects() {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {5, 5, 1}, {6, 5, 1}, {5, 6, 1}};
  m.triangles = {{0, 1, 2}, {1, 3, 2}, {4, 5, 6}};
  m.vertex_attributes = {{"snow_coverage", {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f}},
                         {"object", {0, 0, 0, 0, 1, 1, 1}}};
  m.origin = {746633.0, 4032753.0, 12.5};
  return m;
}

}  // namespace

TEST(MeshIo, PlyRoundTripKeepsEverything) {
  const fs::path path = fs::temp_directory_path() / "drift_mesh_round_trip.ply";
  const Mesh m = two_objects();
  write_ply(m, path);
  const Mesh back = read_ply(path);
  EXPECT_EQ(back.positions, m.positions);
  EXPECT_EQ(back.triangles, m.triangles);
  ASSERT_NE(back.attribute("snow_coverage"), nullptr);
  EXPECT_EQ(*back.attribute("snow_coverage"), *m.attribute("snow_coverage"));
  EXPECT_EQ(back.origin, m.origin);  // to the last bit: UTM metres
  fs::remove(path);
}

TEST(MeshIo, SplitByAttributeGivesEachObjectItsVerticesAndTriangles) {
  const auto parts = split_by_attribute(two_objects(), "object");
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].vertex_count(), 4u);
  EXPECT_EQ(parts[0].triangle_count(), 2u);
  EXPECT_EQ(parts[1].vertex_count(), 3u);
  ASSERT_EQ(parts[1].triangle_count(), 1u);
  EXPECT_EQ(parts[1].triangles[0], (std::array<int, 3>{0, 1, 2}));
  EXPECT_FLOAT_EQ((*parts[1].attribute("snow_coverage"))[0], 0.5f);
  EXPECT_EQ(parts[1].origin, two_objects().origin);
  EXPECT_THROW(split_by_attribute(two_objects(), "colour"), drift::Error);
}

TEST(MeshIo, MalformedPlyIsAClearError) {
  const fs::path path = fs::temp_directory_path() / "drift_mesh_bad.ply";
  write_ply(two_objects(), path);
  fs::resize_file(path, fs::file_size(path) - 7);  // truncated faces
  EXPECT_THROW(read_ply(path), drift::Error);
  std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n";
  try {
    read_ply(path);
    ADD_FAILURE() << "an ASCII PLY must be refused";
  } catch (const drift::Error& e) {
    EXPECT_NE(std::string(e.what()).find("ascii"), std::string::npos) << e.what();
  }
  std::ofstream(path) << "solid cube\n";
  EXPECT_THROW(read_ply(path), drift::Error);
  EXPECT_THROW(read_ply(fs::temp_directory_path() / "drift_no_such_mesh.ply"), drift::Error);
  fs::remove(path);
}

namespace {

// The message of read_obj's refusal of `text`, or "" if it was read.
std::string obj_refusal(const std::string& text) {
  const fs::path path = fs::temp_directory_path() / "drift_mesh_check.obj";
  std::ofstream(path) << text;
  try {
    read_obj(path);
    return "";
  } catch (const drift::Error& e) {
    return e.what();
  }
}

std::string polygon(std::size_t corners) {
  std::ostringstream text;
  for (std::size_t i = 0; i < corners; ++i) {
    const double a = 6.283185307179586 * static_cast<double>(i) / static_cast<double>(corners);
    text << "v " << std::cos(a) << ' ' << std::sin(a) << " 0\n";
  }
  text << 'f';
  for (std::size_t i = 1; i <= corners; ++i) text << ' ' << i;
  text << '\n';
  return text.str();
}

}  // namespace

// tinyobjloader reads "  v nan 0 0" (leading spaces) as 0, "0x1p+200" as 0 and
// 1e39 as infinity: each is refused naming the line.
TEST(MeshIo, ObjCoordinatesThatWouldBeMisreadAreRefusedNamingTheLine) {
  const std::string tail = "v 1 0 0\nv 0 1 0\nf 1 2 3\n";
  EXPECT_EQ(obj_refusal(std::string("v 0 0 0\n").append(tail)), "");
  EXPECT_EQ(obj_refusal(std::string("  v 0 0 -1.5e3\n").append(tail)), "");
  for (const char* bad :
       {"  v nan 0 0\n", "\tv 0 inf 0\n", "v 0x1p+200 0 0\n", "v 0 0 1e39\n", "v 0 0 -nan\n"}) {
    const std::string message = obj_refusal(std::string(bad).append(tail));
    EXPECT_NE(message.find("line 1: vertex coordinate"), std::string::npos) << bad << message;
  }
}

// One face of 40,000 vertices took 10 s to triangulate (quadratic): faces are
// bounded, and a face within the bound still reads.
TEST(MeshIo, ObjFacesOfTooManyVerticesAreRefused) {
  EXPECT_EQ(obj_refusal(polygon(1024)), "");
  const std::string message = obj_refusal(polygon(40000));
  EXPECT_NE(message.find("a face of 40000 vertices"), std::string::npos) << message;
}

// An OBJ's `mtllib` is never opened: "mtllib ../../dev/zero" had read /dev/zero
// for ever and a FIFO had blocked.
TEST(MeshIo, ObjMaterialLibrariesAreNotOpened) {
  const fs::path fifo = fs::temp_directory_path() / "drift_mesh_fifo.mtl";
  fs::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string tail = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  EXPECT_EQ(obj_refusal(std::string("mtllib drift_mesh_fifo.mtl\nusemtl a\n").append(tail)), "");
  EXPECT_EQ(obj_refusal(std::string("mtllib ../../../../../../../../dev/zero\n").append(tail)), "");
  fs::remove(fifo);
}
