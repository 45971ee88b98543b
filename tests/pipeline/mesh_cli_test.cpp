// drift mesh (issue 37 item 4): a DEM window as GLB that Assimp reads back on
// the DEM's cells, usage errors exit 2, and a scene's objects taken as GLB and
// STL land where the same mesh as OBJ lands.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "pipeline/object_list.h"
#include "terrain/mesh_io.h"
#include "terrain/raster_io.h"
#include "tests/test_files.h"
#include "tests/utm_fixture.h"

namespace fs = std::filesystem;
using namespace drift::testing;  // test_dir, put, run_drift, drift_log

namespace {

// drift mesh DEM FLAGS -o OUT, run in d; its exit status.
int mesh(const fs::path& dem, const std::string& flags, const fs::path& out, const fs::path& d) {
  return run_drift("mesh " + dem.string() + " " + flags + " -o " + out.string(), d);
}

// A 40 x 30 DEM of 10 m cells at UTM magnitude: a tilted plane with a peak.
fs::path make_dem(const fs::path& d) {
  return drift::testing::write_dem(d, 40, 30, 700000.0, 4000300.0, 10.0, "", [](int x, int r) {
    return x == 20 && r == 10 ? 1500.0f
                              : 1000.0f + 2.0f * static_cast<float>(x) - static_cast<float>(r);
  });
}

// The last run in d was refused: its log names `what` and `out` was not written.
void expect_refused(const fs::path& d, const std::string& what, const fs::path& out) {
  EXPECT_NE(drift_log(d).find(what), std::string::npos) << drift_log(d);
  EXPECT_FALSE(fs::exists(out)) << out;
}

}  // namespace

TEST(MeshCli, CropAsGlbLiesOnTheDemsCells) {
  const fs::path d = test_dir("mesh_cli");
  const fs::path dem = make_dem(d);
  // Cells 10..29 x 5..14: centres x 700105..700295, y 4000155..4000245.
  ASSERT_EQ(mesh(dem, "--crop 700100,4000150,700300,4000250", d / "crop.glb", d), 0)
      << drift_log(d);
  EXPECT_NE(drift_log(d).find("200 vertices, 342 triangles"), std::string::npos) << drift_log(d);
  const drift::terrain::Mesh m = drift::terrain::read_mesh(d / "crop.glb");
  ASSERT_EQ(m.positions.size(), 200u);
  // Origin (in the file's extras) at cell (10, 5)'s centre; positions metres from it, z up.
  const Eigen::Vector3d origin(700105.0, 4000245.0, 0.0);
  float top = 0;
  Eigen::Vector3f peak = Eigen::Vector3f::Zero();
  for (const auto& p : m.positions) {
    if (p.z() > top) top = p.z(), peak = p;
  }
  EXPECT_FLOAT_EQ(top, 1500.0f);
  EXPECT_FLOAT_EQ(origin.x() + peak.x(), 700205.0);   // cell 20's centre
  EXPECT_FLOAT_EQ(origin.y() + peak.y(), 4000195.0);  // row 10's centre
  EXPECT_NE(drift::testing::slurp(d / "crop.glb").find("\"drift_origin\":[700105,4000245,0]"),
            std::string::npos);
}

TEST(MeshCli, DecimateKeepsEveryCellWithinTheBound) {
  const fs::path d = test_dir("mesh_cli");
  const fs::path dem = make_dem(d);  // a plane with one spike: few triangles but round the spike
  ASSERT_EQ(mesh(dem, "--decimate 0.01", d / "dec.glb", d), 0) << drift_log(d);
  EXPECT_NE(drift_log(d).find("of 2262 triangles; largest vertical error 0 m (bound 0.01 m)"),
            std::string::npos)
      << drift_log(d);
  const drift::terrain::Mesh m = drift::terrain::read_mesh(d / "dec.glb");
  EXPECT_LT(m.triangles.size(), 2262u / 4);
  bool spike = false;
  for (const auto& p : m.positions) spike = spike || p.z() == 1500.0f;
  EXPECT_TRUE(spike);
  // Every cell centre lies on the mesh: the plane's height where it is not the spike.
  const drift::terrain::HeightField g = drift::terrain::read_raster(dem);
  double worst = 0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3f a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
    const Eigen::Vector3f n = (b - a).cross(c - a);
    ASSERT_GT(n.z(), 0.0f);  // counter-clockwise seen from above
    for (int r = 0; r < g.height(); ++r) {
      for (int x = 0; x < g.width(); ++x) {
        const Eigen::Vector2f p(10.0f * x, -10.0f * r);  // metres from cell (0, 0)'s centre
        auto side = [&](const Eigen::Vector3f& u, const Eigen::Vector3f& v) {
          return (v.x() - u.x()) * (p.y() - u.y()) - (v.y() - u.y()) * (p.x() - u.x());
        };
        if (side(a, b) < -1e-3f || side(b, c) < -1e-3f || side(c, a) < -1e-3f) continue;
        const float z = a.z() - (n.x() * (p.x() - a.x()) + n.y() * (p.y() - a.y())) / n.z();
        worst = std::max(worst, std::abs(static_cast<double>(z - g(x, r))));
      }
    }
  }
  EXPECT_LE(worst, 0.01);
  EXPECT_EQ(mesh(dem, "--decimate 1 --step 2", d / "b.glb", d), 2);
  EXPECT_EQ(mesh(dem, "--decimate=-1", d / "b.glb", d), 2);
  expect_refused(d, "--decimate", d / "b.glb");
}

TEST(MeshCli, UsageErrorsExitTwo) {
  const fs::path d = test_dir("mesh_cli");
  const fs::path dem = make_dem(d);
  EXPECT_EQ(mesh(dem, "", d / "crop.xyz", d), 2);
  EXPECT_NE(drift_log(d).find(".glb, .gltf, .fbx, .stl, .obj or .ply"), std::string::npos)
      << drift_log(d);
  EXPECT_EQ(mesh(dem, "--step 0", d / "a.glb", d), 2);
  EXPECT_EQ(mesh(dem, "--attribute cover", d / "a.glb", d), 2);
  EXPECT_EQ(run_drift("mesh -o " + (d / "a.glb").string(), d), 2);
  // A box beside the DEM is bad input (exit 1), naming the fix.
  EXPECT_EQ(mesh(dem, "--crop 0,0,10,10", d / "a.glb", d), 1);
  expect_refused(d, "drift info", d / "a.glb");
}

TEST(MeshCli, AttributeNamesThatWouldBreakTheFileAreRefused) {
  // 'a b' wrote "property float a b" into the PLY's header (unreadable); a
  // name given twice, or twice but for case, wrote two _A attributes into one
  // glTF primitive (invalid); 'nz' shadowed the normal. All exited 0.
  const fs::path d = test_dir("mesh_cli_names");
  const fs::path dem = make_dem(d);
  const std::string a = " --attribute ";
  for (const std::string& attributes :
       {a + "'a b=" + dem.string() + "'", a + "a=" + dem.string() + a + "a=" + dem.string(),
        a + "a=" + dem.string() + a + "A=" + dem.string(), a + "nz=" + dem.string()}) {
    SCOPED_TRACE(attributes);
    for (const char* out : {"m.ply", "m.glb"}) {
      EXPECT_EQ(run_drift("mesh " + dem.string() + attributes + " -o " + (d / out).string(), d), 2);
      expect_refused(d, "--attribute", d / out);
    }
  }
  EXPECT_EQ(run_drift("mesh " + dem.string() + a + "snow_depth2=" + dem.string() + " -o " +
                          (d / "m.ply").string(),
                      d),
            0)
      << drift_log(d);
}

TEST(MeshCli, ObjectsTakeGlbAndStlWhereTheObjLands) {
  const fs::path d = test_dir("mesh_cli");
  // The hut as OBJ (z up as stored), and as GLB and STL written from it.
  const drift::terrain::Mesh hut =
      drift::terrain::read_mesh(DRIFT_SOURCE_DIR "/data/objects/hut.obj");
  drift::terrain::write_mesh(hut, d / "hut.glb");
  drift::terrain::write_mesh(hut, d / "hut.stl");
  fs::copy_file(DRIFT_SOURCE_DIR "/data/objects/hut.obj", d / "hut.obj");
  std::string objects;
  for (const char* f : {"hut.obj", "hut.glb", "hut.stl"})
    objects += std::string("[[objects]]\nmesh = \"") + f +
               "\"\nposition = [700100, 4000100, 1000]\nrotate_z = 30\nscale = 2\n";
  put(d / "objects.toml", objects);
  const auto placed = drift::pipeline::read_objects_file(d / "objects.toml");
  ASSERT_EQ(placed.size(), 3u);
  auto bounds = [](const drift::terrain::Mesh& m) {
    Eigen::Vector3f lo = m.positions[0], hi = lo;
    for (const auto& p : m.positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    return std::pair{lo, hi};
  };
  const auto [lo, hi] = bounds(placed[0].mesh);
  for (std::size_t k = 1; k < 3; ++k) {
    const auto [l, h] = bounds(placed[k].mesh);
    EXPECT_LT((l - lo).norm(), 1e-4f) << k;
    EXPECT_LT((h - hi).norm(), 1e-4f) << k;
    EXPECT_EQ(placed[k].mesh.triangle_count(), placed[0].mesh.triangle_count()) << k;
  }
}

// Blender 3.4's binary FBX and Collada exports of the hut (made once with
// Blender's exporters: tests/pipeline/meshes/README.md) read through Assimp
// into the same box as the OBJ they came from, in metres and z up.
TEST(MeshCli, BlendersBinaryFbxAndDaeLandWhereTheObjLands) {
  const drift::terrain::Mesh obj =
      drift::terrain::read_mesh(DRIFT_SOURCE_DIR "/data/objects/hut.obj");
  auto bounds = [](const drift::terrain::Mesh& m) {
    Eigen::Vector3f lo = m.positions[0], hi = lo;
    for (const auto& p : m.positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    return std::pair{lo, hi};
  };
  const auto [lo, hi] = bounds(obj);
  for (const char* f : {"hut_blender_binary.fbx", "hut_blender.dae"}) {
    const drift::terrain::Mesh m =
        drift::terrain::read_mesh(fs::path(DRIFT_SOURCE_DIR "/tests/pipeline/meshes") / f);
    const auto [l, h] = bounds(m);
    EXPECT_LT((l - lo).norm(), 1e-4f) << f << " low " << l.transpose() << " vs " << lo.transpose();
    EXPECT_LT((h - hi).norm(), 1e-4f) << f << " high " << h.transpose() << " vs " << hi.transpose();
    EXPECT_EQ(m.triangle_count(), obj.triangle_count()) << f;
  }
}

// Snowy objects (--snow-objects) are read like every mesh, but only PLY and
// GLB carry the snow per vertex: a GLB without it is refused naming the fix.
TEST(MeshCli, SnowObjectsOtherThanPlyAreRefusedNamingThePly) {
  const fs::path d = test_dir("mesh_cli");
  const fs::path dem = make_dem(d);
  drift::terrain::Mesh hut = drift::terrain::read_mesh(DRIFT_SOURCE_DIR "/data/objects/hut.obj");
  drift::terrain::write_mesh(hut, d / "snowy.glb");
  put(d / "scene.toml", "[terrain]\nraster = \"dem.tif\"\n[[objects]]\nmesh = \"" DRIFT_SOURCE_DIR
                        "/data/objects/hut.obj\"\nposition = [700100, 4000100, 1000]\n");
  EXPECT_EQ(
      run_drift("render " + (d / "scene.toml").string() + " --snow-objects " +
                    (d / "snowy.glb").string() + " --size 8x6 --spp 1 -o " + (d / "f.png").string(),
                d),
      1);
  EXPECT_NE(drift_log(d).find("snowy.glb' has no per-vertex snow"), std::string::npos)
      << drift_log(d);
  expect_refused(d, "--mesh-out OBJECTS.ply", d / "f.png");
}

// drift snow fall --mesh-out x.glb round-trips into --snow-objects x.glb
// (drift's own GLB reader keeps the custom attributes Assimp drops,
// assimp#4830): the frame is the PLY's byte for byte, and the snow shows (the
// frame without the snowy objects differs).
TEST(MeshCli, SnowObjectsAsGlbRenderAsThePly) {
  const fs::path d = test_dir("mesh_cli");
  const fs::path dem = make_dem(d);
  put(d / "objects.toml", "[[objects]]\nmesh = \"" DRIFT_SOURCE_DIR
                          "/data/objects/hut.obj\"\nposition = [700100, 4000100, 1000]\n");
  for (const char* ext : {"ply", "glb"}) {
    ASSERT_EQ(
        run_drift("snow fall " + dem.string() + " --objects " + (d / "objects.toml").string() +
                      " --rate 0.02 --hours 10 --maps 2 --threads 1 -o " +
                      (d / (std::string("depth_") + ext + ".tif")).string() + " --mesh-out " +
                      (d / (std::string("snowy.") + ext)).string(),
                  d),
        0)
        << drift_log(d);
  }
  put(d / "scene.toml",
      "[terrain]\nraster = \"dem.tif\"\nobjects = \"objects.toml\"\n"
      "[camera]\nfrom = [700070, 4000070, 1025]\nto = [700100, 4000100, 1003]\nfov = 30\n");
  auto render = [&](const std::string& snow, const char* out) {
    EXPECT_EQ(
        run_drift("render " + (d / "scene.toml").string() + snow +
                      " --size 48x32 --spp 2 --exposure 0 --threads 1 -o " + (d / out).string(),
                  d),
        0)
        << drift_log(d);
    return slurp(d / out);
  };
  const std::string ply = render(" --snow-objects " + (d / "snowy.ply").string(), "ply.png");
  const std::string glb = render(" --snow-objects " + (d / "snowy.glb").string(), "glb.png");
  const std::string bare = render("", "bare.png");
  ASSERT_FALSE(ply.empty());
  EXPECT_TRUE(glb == ply) << "the GLB's snowy objects render otherwise than the PLY's";
  EXPECT_TRUE(bare != ply) << "the snowy objects do not show in the frame";
}
