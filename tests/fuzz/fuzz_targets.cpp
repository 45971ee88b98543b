#include "tests/fuzz/fuzz_targets.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "pipeline/object_list.h"
#include "pipeline/scene_file.h"
#include "pipeline/track_file.h"
#include "render/image_compare.h"
#include "render/image_io.h"
#include "render/tiles.h"
#include "terrain/error.h"
#include "terrain/import.h"
#include "terrain/mesh_io.h"
#include "terrain/raster_io.h"

namespace drift::fuzz {

namespace fs = std::filesystem;

namespace {

// The readers take paths: each input goes to a file of this process, named with
// the extension the reader chooses its format by.
fs::path as_file(const std::uint8_t* data, std::size_t size, const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("drift-fuzz-" + std::to_string(getpid()));
  fs::create_directories(dir);
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

void scene(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "scene.toml");
  refusals_allowed([&] { pipeline::read_scene_file(file); });
}

void objects(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "objects.toml");
  refusals_allowed([&] { pipeline::read_objects_file(file); });
}

// drift marks --track: [[objects]] with keyframes, material, step.
void track(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "track.toml");
  refusals_allowed([&] { pipeline::read_track_file(file); });
}

void obj(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "mesh.obj");
  refusals_allowed([&] {
    const terrain::Mesh m = terrain::read_obj(file, size > 0 && data[0] % 2);
    for (const auto& p : m.positions) {
      if (!p.allFinite()) throw std::logic_error("read_obj let a non-finite vertex through");
    }
  });
}

void ply(const std::uint8_t* data, std::size_t size) {
  const fs::path file = as_file(data, size, "mesh.ply");
  refusals_allowed([&] {
    const terrain::Mesh m = terrain::read_ply(file);
    for (const auto& p : m.positions) {
      if (!p.allFinite()) throw std::logic_error("read_ply let a non-finite vertex through");
    }
  });
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

const std::vector<Target>& targets() {
  static const std::vector<Target> all = {
      {"raster", raster}, {"scene", scene}, {"objects", objects}, {"track", track},
      {"obj", obj},       {"ply", ply},     {"image", image}};
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
