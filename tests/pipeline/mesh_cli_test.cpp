// drift mesh (issue 37 item 4): a DEM window as GLB that Assimp reads back on
// the DEM's cells, usage errors exit 2, and a scene's objects taken as GLB and
// STL land where the same mesh as OBJ lands.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "pipeline/object_list.h"
#include "terrain/mesh_io.h"
#include "terrain/raster_io.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using drift::testing::drift_log;
using drift::testing::put;
using drift::testing::run_drift;
using drift::testing::test_dir;

namespace {

// A 40 x 30 DEM of 10 m cells at UTM magnitude: a tilted plane with a peak.
fs::path make_dem(const fs::path& d) {
  drift::terrain::HeightField g(40, 30, 0.0f);
  g.geo().geotransform = {700000.0, 10.0, 0.0, 4000300.0, 0.0, -10.0};
  for (int r = 0; r < 30; ++r)
    for (int x = 0; x < 40; ++x)
      g(x, r) = 1000.0f + 2.0f * static_cast<float>(x) - static_cast<float>(r);
  g(20, 10) = 1500.0f;
  const fs::path dem = d / "dem.tif";
  drift::terrain::write_geotiff(g, dem);
  return dem;
}

}  // namespace

TEST(MeshCli, CropAsGlbLiesOnTheDemsCells) {
  const fs::path d = test_dir("mesh_cli");
  const fs::path dem = make_dem(d);
  // Cells 10..29 x 5..14: centres x 700105..700295, y 4000155..4000245.
  ASSERT_EQ(run_drift("mesh " + dem.string() + " --crop 700100,4000150,700300,4000250 -o " +
                          (d / "crop.glb").string(),
                      d),
            0)
      << drift_log(d);
  EXPECT_NE(drift_log(d).find("200 vertices, 342 triangles"), std::string::npos) << drift_log(d);
  const drift::terrain::Mesh m = drift::terrain::read_mesh(d / "crop.glb");
  ASSERT_EQ(m.positions.size(), 200u);
  // Origin (in the file's extras) at cell (10, 5)'s centre; positions metres from it, z up.
  const Eigen::Vector3d origin(700105.0, 4000245.0, 0.0);
  float top = 0;
  Eigen::Vector3f peak;
  for (const auto& p : m.positions) {
    if (p.z() > top) top = p.z(), peak = p;
  }
  EXPECT_FLOAT_EQ(top, 1500.0f);
  EXPECT_FLOAT_EQ(origin.x() + peak.x(), 700205.0);   // cell 20's centre
  EXPECT_FLOAT_EQ(origin.y() + peak.y(), 4000195.0);  // row 10's centre
  EXPECT_NE(drift::testing::slurp(d / "crop.glb").find("\"drift_origin\":[700105,4000245,0]"),
            std::string::npos);
}

TEST(MeshCli, UsageErrorsExitTwo) {
  const fs::path d = test_dir("mesh_cli");
  const fs::path dem = make_dem(d);
  EXPECT_EQ(run_drift("mesh " + dem.string() + " -o " + (d / "crop.xyz").string(), d), 2);
  EXPECT_NE(drift_log(d).find(".glb, .gltf, .fbx, .stl, .obj or .ply"), std::string::npos)
      << drift_log(d);
  EXPECT_EQ(run_drift("mesh " + dem.string() + " --step 0 -o " + (d / "a.glb").string(), d), 2);
  EXPECT_EQ(
      run_drift("mesh " + dem.string() + " --attribute cover -o " + (d / "a.glb").string(), d), 2);
  EXPECT_EQ(run_drift("mesh -o " + (d / "a.glb").string(), d), 2);
  // A box beside the DEM is bad input (exit 1), naming the fix.
  EXPECT_EQ(run_drift("mesh " + dem.string() + " --crop 0,0,10,10 -o " + (d / "a.glb").string(), d),
            1);
  EXPECT_NE(drift_log(d).find("drift info"), std::string::npos) << drift_log(d);
  EXPECT_FALSE(fs::exists(d / "a.glb"));
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
      EXPECT_NE(drift_log(d).find("--attribute"), std::string::npos) << drift_log(d);
      EXPECT_FALSE(fs::exists(d / out));
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
