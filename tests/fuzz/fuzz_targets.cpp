#include "tests/fuzz/fuzz_targets.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "pipeline/object_list.h"
#include "pipeline/scene_file.h"
#include "pipeline/soil_scenario_file.h"
#include "pipeline/track_file.h"
#include "render/image_compare.h"
#include "render/image_io.h"
#include "render/tiles.h"
#include "terrain/error.h"
#include "terrain/import.h"
#include "terrain/marks/marks.h"
#include "terrain/mesh_io.h"
#include "terrain/raster_io.h"
#include "terrain/soil/scenario.h"

namespace drift::fuzz {

namespace fs = std::filesystem;

namespace {

bool g_bounded = false;  // bound_work_per_input()

// The files a fuzzed file may name by a relative path (the seeds do): small
// meshes and a metric DEM, so that the readers go on past the reference.
void write_fixtures(const fs::path& dir) {
  const char* tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  for (const char* name : {"ball.obj", "rock.obj", "hut.obj", "shoe.obj"})
    std::ofstream(dir / name) << tetra;
  terrain::HeightField dem(24, 24, 10.0f, terrain::local_georeference(1.0));
  for (int r = 0; r < 24; ++r)
    for (int c = 0; c < 24; ++c) dem(c, r) = 10.0f + 0.25f * static_cast<float>(c + r);
  terrain::write_geotiff(dem, dir / "dem.tif");
}

// The readers take paths: each input goes to a file of this process, named with
// the extension the reader chooses its format by.
// The directory goes when the process exits (a fuzzer at its time limit, the
// replay); one of each run had stayed behind in /tmp. Registered after `dir`
// is made, the removal runs before `dir` is destroyed.
const fs::path& fixture_dir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("drift-fuzz-" + std::to_string(getpid()));
    fs::create_directories(d);
    write_fixtures(d);
    return d;
  }();
  static const int removal = std::atexit([] {
    std::error_code ignored;
    fs::remove_all(fixture_dir(), ignored);
  });
  (void)removal;
  return dir;
}

fs::path as_file(const std::uint8_t* data, std::size_t size, const std::string& name) {
  const fs::path& dir = fixture_dir();
  const fs::path file = dir / name;
  std::ofstream(file, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return file;
}

template <class F>
void refusals_allowed(F&& reader) {
  try {
    reader();
  } catch (const drift::Error&) {
    // A clear refusal is the right answer to a bad file.
  }
}

// DEM import through our checks: header, cells, nodata filling, heights; with
// the first byte choosing the format GDAL is told by the name.
void raster(const std::uint8_t* data, std::size_t size) {
  static const char* names[] = {"in.tif", "in.asc", "in.hgt", "in.dem"};
  const char* name = names[size > 0 ? data[0] % 4 : 0];
  const fs::path file = as_file(data, size, name);
  refusals_allowed([&] {
    const terrain::ImportResult r = terrain::import_dem(file, {});
    for (float v : r.grid.values()) {
      if (!std::isfinite(v)) throw std::logic_error("import let a non-finite height through");
    }
  });
}

// The scene TOML, then what it names loaded as drift render loads it (the
// fixture dem.tif stands for every raster: terrain, surround, albedo map,
// layer masks, [snow] cover and depth), without building the ray tracer.
void scene(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "scene.toml");
  refusals_allowed([&] {
    pipeline::SceneFile scene = pipeline::read_scene_file(file);
    pipeline::load_scene_terrain(scene);
  });
}

void objects(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "objects.toml");
  refusals_allowed([&] { pipeline::read_objects_file(file); });
}

// drift marks --track: [[objects]] with keyframes, material, step. A short
// track is also run on a small flat ground under its first keyframe, so the
// values it holds reach the marks geometry (windows, sweeps, sub-steps).
void track(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "track.toml");
  refusals_allowed([&] {
    const pipeline::TrackFile t = pipeline::read_track_file(file);
    double t0 = 1e300, t1 = -1e300;
    for (const marks::MarkObject& o : t.objects)
      t0 = std::min(t0, o.trajectory.start()), t1 = std::max(t1, o.trajectory.end());
    if ((t1 - t0) / t.step > 8) return;  // a few steps: many inputs a second
    const Eigen::Vector3d at = t.objects.front().trajectory.keys.front().position;
    // The ground lies under the first keyframe; a keyframe kilometres below it
    // cuts a hole as deep, which the erosion passes then take seconds to fill
    // (under ASan; round 3 ran 117 inputs in 4 min). Fuzzing, keyframes within
    // 2 m of the first (every path still meets the 0.64 m ground and digs
    // through it); the replay runs every kept input whole.
    if (g_bounded)
      for (const marks::MarkObject& o : t.objects)
        for (const auto& key : o.trajectory.keys)
          if (!((key.position - at).norm() <= 2.0)) return;
    terrain::GeoReference geo = terrain::local_georeference(0.02);
    geo.geotransform[0] = at.x() - 0.32, geo.geotransform[3] = at.y() + 0.32;
    const terrain::HeightField ground(32, 32, static_cast<float>(at.z() - 0.02), geo);
    marks::MarksOptions o;
    o.step = t.step;
    o.camera = t.camera;
    const marks::Material m = t.material.value_or(*marks::material_preset("sand"));
    marks::simulate_marks(ground, t.objects, marks::MaterialField{{m}, {}}, o);
  });
}

// drift soil SCENARIO.toml: grid, soil, bodies, terrain (a DEM window or a
// voxel terrain). Small grids are also voxelised and stepped twice, so the
// scenario's values reach the voxelisation and the first steps.
void scenario(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "scenario.toml");
  refusals_allowed([&] {
    const soil::SoilScenario sc = pipeline::read_soil_scenario(file);
    const double voxels = double(sc.shape.nx) * sc.shape.ny * sc.shape.nz;
    if (voxels > 24.0 * 24 * 24) return;  // small: many inputs a second
    soil::SoilSimulation sim = soil::make_simulation(sc);
    sim.step();
    sim.step();
    const std::vector<float>& rho = sim.state().rho;
    for (float v : rho) {
      if (!std::isfinite(v)) throw std::logic_error("soil let a non-finite density through");
    }
  });
}

// What every mesh reader must hand on, whatever the bytes: finite vertices,
// faces naming vertices that exist, an attribute value a vertex.
void check_mesh(const terrain::Mesh& m, const std::string& reader) {
  for (const auto& p : m.positions)
    if (!p.allFinite()) throw std::logic_error(reader + " let a non-finite vertex through");
  for (const auto& t : m.triangles)
    for (int v : t)
      if (v < 0 || static_cast<std::size_t>(v) >= m.positions.size())
        throw std::logic_error(reader + " let a face name a missing vertex");
  for (const auto& [name, values] : m.vertex_attributes)
    if (values.size() != m.positions.size())
      throw std::logic_error(reader + " gave attribute '" + name + "' a wrong length");
}

void obj(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "mesh.obj");
  refusals_allowed(
      [&] { check_mesh(terrain::read_obj(file, size > 0 && data[0] % 2), "read_obj"); });
}

void ply(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "mesh.ply");
  refusals_allowed([&] { check_mesh(terrain::read_ply(file), "read_ply"); });
}

// Meshes through Assimp (terrain/mesh_assimp.cpp), the format by the bytes'
// start as a user's file would be named: GLB, glTF JSON, ASCII FBX, else STL.
void mesh(const std::uint8_t* data, std::size_t size) {
  const std::string head(reinterpret_cast<const char*>(data), std::min<std::size_t>(size, 8));
  const char* name = head.rfind("glTF", 0) == 0    ? "mesh.glb"
                     : head.rfind("{", 0) == 0     ? "mesh.gltf"
                     : head.rfind("; FBX", 0) == 0 ? "mesh.fbx"
                                                   : "mesh.stl";
  const fs::path file = as_file(data, size, name);
  refusals_allowed([&] { check_mesh(terrain::read_mesh(file), "read_mesh"); });
}

// drift's own GLB reader (terrain/mesh_glb.cpp: --snow-objects x.glb).
void glb(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "mesh.glb");
  refusals_allowed([&] { check_mesh(terrain::read_glb(file), "read_glb"); });
}

// EXR and PNG tiles as merge and compare read them.
void image(const std::uint8_t* data, std::size_t size) {
  const bool png = size >= 8 && data[1] == 'P' && data[2] == 'N' && data[3] == 'G';
  const fs::path file = as_file(data, size, png ? "tile.png" : "tile.exr");
  refusals_allowed([&] {
    const render::Image a = render::read_image(file);
    render::merge_tiles({a}, {file});
    render::compare_images(a, a, {});
  });
}

}  // namespace

void bound_work_per_input() { g_bounded = true; }

const std::vector<Target>& targets() {
  static const std::vector<Target> all = {
      {"raster", raster},     {"scene", scene}, {"objects", objects}, {"track", track},
      {"scenario", scenario}, {"obj", obj},     {"ply", ply},         {"image", image},
      {"mesh", mesh},         {"glb", glb}};
  return all;
}

bool run_target(const std::string& name, const std::uint8_t* data, std::size_t size) {
  for (const Target& t : targets()) {
    if (name == t.name) {
      t.run(data, size);
      return true;
    }
  }
  return false;
}

}  // namespace drift::fuzz
