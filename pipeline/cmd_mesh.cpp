// drift mesh RASTER -o OUT.glb: a DEM (or a part of it) or any product raster
// (marked ground, snow surface, dunes) as a triangle mesh for Blender, game
// engines and viewers: glTF/GLB, FBX, STL, OBJ or PLY by the output's extension.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "pipeline/cli.h"
#include "pipeline/object_list.h"
#include "terrain/height_mesh.h"
#include "terrain/memory.h"
#include "terrain/mesh_io.h"
#include "terrain/output_set.h"
#include "terrain/raster_io.h"

namespace drift::pipeline {

namespace {

struct MeshCommand {
  std::string raster, output;
  std::vector<double> crop;
  std::vector<std::string> attributes;  // NAME=RASTER
  int step = 1;
  std::optional<double> decimate;  // metres of vertical error (terrain/mesh_rtin.h)
};

void run_mesh(const MeshCommand& c) {
  std::vector<std::pair<std::string, std::string>> named;  // name, raster
  std::vector<std::filesystem::path> inputs = {c.raster};
  for (const std::string& a : c.attributes) {
    const auto eq = a.find('=');
    if (eq == 0 || eq == std::string::npos || eq + 1 == a.size())
      usage_error("--attribute '" + a + "' must be NAME=RASTER, e.g. snow_coverage=cover.tif");
    const std::string name = a.substr(0, eq);
    // A name goes into the PLY header as one word and into glTF as _NAME in
    // capitals: a space broke the PLY's header, and two names alike but for
    // case (or given twice) made an invalid glTF (two attributes of one name).
    if (!std::all_of(name.begin(), name.end(),
                     [](unsigned char ch) { return std::isalnum(ch) || ch == '_'; }))
      usage_error("--attribute '" + a + "': NAME must be letters, digits and _, e.g. snow_depth");
    auto upper = [](std::string t) {
      for (char& ch : t) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
      return t;
    };
    // Messages built by append: clang-tidy (performance-inefficient-string-concatenation).
    std::string problem = "--attribute '" + a + "': ";
    for (const std::string reserved : {"X", "Y", "Z", "NX", "NY", "NZ"})
      if (upper(name) == reserved)
        usage_error(
            problem.append(name).append(" is a vertex coordinate or normal; give another NAME"));
    for (const auto& [other, path] : named)
      if (upper(other) == upper(name))
        usage_error(
            problem.append("the NAME '")
                .append(other)
                .append("' is given already (names differing only in case are one in glTF)"));
    named.emplace_back(name, a.substr(eq + 1));
    inputs.emplace_back(a.substr(eq + 1));
  }
  // The path's own problems (a device, an input) first, as every command reports them.
  OutputSet outputs({c.output}, inputs);
  if (!terrain::is_mesh_output(c.output))
    usage_error("-o '" + c.output + "' must end in .glb, .gltf, .fbx, .stl, .obj or .ply");
  if (c.decimate && c.step != 1)
    usage_error("--decimate and --step both choose the vertices; give one of them");
  if (c.decimate && !(*c.decimate >= 0.0 && std::isfinite(*c.decimate)))
    usage_error("--decimate " + std::to_string(*c.decimate) +
                " must be a vertical error of 0 metres or more, e.g. --decimate 0.5");
  terrain::ReadOptions read;
  const terrain::RasterHeader header = terrain::read_raster_header(c.raster);
  if (!c.crop.empty()) {
    read.window =
        terrain::crop_window(header, {c.crop[0], c.crop[1], c.crop[2], c.crop[3]}, c.raster);
  }
  // Everything the run holds at its peak, before any of it is read: the
  // rasters, the mesh and what its format's writer builds (a 2048 x 2048 DEM
  // as FBX reached 4 GiB unchecked).
  const std::uint64_t w = read.window ? read.window->width : header.width,
                      h = read.window ? read.window->height : header.height;
  const std::uint64_t cols = (w + c.step - 2) / c.step + 1, rows = (h + c.step - 2) / c.step + 1;
  // The rasters (4 bytes a cell each), and the vertex index over their grid
  // (4 more) while the mesh is built.
  const std::uint64_t rasters = w * h * 4 * (1 + named.size()), index = w * h * 4;
  const std::string fix =
      "crop it (--crop), keep fewer cells (--step N), or write .ply or .obj, which stream";
  if (!c.decimate) {
    require_memory(rasters + index +
                       terrain::mesh_and_write_bytes(c.output, cols * rows,
                                                     2 * (cols - 1) * (rows - 1), named.size()),
                   "a mesh of " + std::to_string(cols) + " x " + std::to_string(rows) +
                       " vertices written as '" + c.output + "'",
                   fix);
  }
  // --decimate: RTIN's error grid (a float a point of the (2^k + 1)^2 square
  // holding the raster) is counted up front; the triangle list (24 B a
  // triangle) and the mesh once the bound has decided how many it keeps,
  // each beside what is alive with it: the error grid is freed before the
  // mesh is built, the list and the index before it is written. Counted at
  // worst, every triangle kept, the estimate was 7.7 times the peak at 0.5 m
  // on 3000^2 (MemoryEstimate.MeshDecimated).
  std::uint64_t rtin = 0;
  if (c.decimate) {
    std::uint64_t side = 2;
    while (side + 1 < std::max(w, h)) side *= 2;
    rtin = (side + 1) * (side + 1) * sizeof(float);
    require_memory(rasters + rtin,
                   "RTIN's error grid of " + std::to_string(side + 1) + " x " +
                       std::to_string(side + 1) + " points over '" + c.raster + "'",
                   fix);
  }
  const auto decimated_size = [&](std::uint64_t vertices, std::uint64_t triangles) {
    const std::uint64_t list = triangles * 24;
    const std::uint64_t mesh = vertices * (24 + 4 * named.size()) + triangles * 12;  // no writer
    const std::uint64_t write =
        terrain::mesh_and_write_bytes(c.output, vertices, triangles, named.size());
    require_memory(rasters + std::max({rtin + list, list + index + mesh, write}),
                   "a mesh decimated to " + std::to_string(triangles) + " triangles written as '" +
                       c.output + "'",
                   "give a larger --decimate, crop it (--crop), or write .ply or .obj, which "
                   "stream");
  };
  const terrain::HeightField heights = terrain::read_raster(c.raster, read);
  require_metric_crs(heights, c.raster);
  std::vector<std::pair<std::string, terrain::HeightField>> attributes;
  attributes.reserve(named.size());
  for (const auto& [name, path] : named)
    attributes.emplace_back(name, terrain::read_raster(path, read));
  double error = 0.0;
  const terrain::Mesh mesh = c.decimate
                                 ? terrain::decimated_height_field_mesh(
                                       heights, *c.decimate, attributes, &error, decimated_size)
                                 : terrain::height_field_mesh(heights, c.step, attributes);
  terrain::write_mesh(mesh, c.output);
  outputs.commit();
  if (c.decimate) {
    std::printf(
        "mesh: decimated to %zu of %zu triangles; largest vertical error %.4g m (bound %g m)\n",
        mesh.triangle_count(),
        2 * static_cast<std::size_t>(heights.width() - 1) * (heights.height() - 1), error,
        *c.decimate);
  }
  std::printf(
      "mesh: wrote %s (%zu vertices, %zu triangles; origin %.3f, %.3f in the raster's CRS)\n",
      c.output.c_str(), mesh.vertex_count(), mesh.triangle_count(), mesh.origin.x(),
      mesh.origin.y());
}

}  // namespace

void mesh_flags(CLI::App* sub, MeshCommand* c) {
  sub->add_option("raster", c->raster, "heights: a metric DEM or product raster (GeoTIFF, ...)")
      ->required();
  sub->add_option("-o,--output", c->output,
                  "mesh file: .glb, .gltf, .fbx, .stl, .obj or .ply (by extension)")
      ->required();
  sub->add_option("--crop", c->crop, "xmin,ymin,xmax,ymax in the raster's own CRS")
      ->expected(4)
      ->delimiter(',');
  whole_in_range(
      sub->add_option("--step", c->step,
                      "a vertex every STEP cells (1: every cell; 4: 1/16 the triangles)"),
      1, 1 << 16)
      ->capture_default_str();
  sub->add_option("--decimate", c->decimate,
                  "ERR: the fewest triangles within ERR metres (vertically) of every cell "
                  "centre, crack-free (a right-triangulated irregular network); instead of --step");
  sub->add_option("--attribute", c->attributes,
                  "NAME=RASTER: another raster of the same grid as a per-vertex attribute "
                  "(glTF: custom attribute _NAME; PLY: property NAME), e.g. "
                  "snow_coverage=cover.tif; repeatable")
      ->allow_extra_args(false);  // one NAME=RASTER a flag: a raster after it stays the raster
}

DRIFT_COMMAND(65, "mesh",
              "a DEM or product raster as a triangle mesh: glTF/GLB, FBX, STL, OBJ or PLY (metres; "
              "glTF and FBX y up, the others z up)",
              mesh_flags, run_mesh);

}  // namespace drift::pipeline
