// drift marks GROUND.tif --track TRACK.toml -o OUT.tif: marks that objects
// moving along keyframes leave in soft ground (paper 000, terrain/marks/marks.h).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/cli.h"
#include "pipeline/object_list.h"
#include "pipeline/parameter_flags.h"
#include "pipeline/progress_bar.h"
#include "pipeline/track_file.h"
#include "terrain/error.h"
#include "terrain/height_change.h"
#include "terrain/marks/marks.h"
#include "terrain/marks/marks_blocks.h"
#include "terrain/marks/marks_parameters.h"
#include "terrain/mesh_io.h"
#include "terrain/output_set.h"
#include "terrain/raster_io.h"

namespace drift::pipeline {

namespace {

namespace fs = std::filesystem;

struct MarksCommand {
  std::string ground, track, output, material, disturbed, frames, snow_depth, materials, posed,
      renderer = "cpu";
  double snow_min = 0.01;
  int block = 0, halo = 64;  // --block, --halo: block by block (marks_blocks.h)
  std::optional<double> posed_at;
  bool add_snow = false;
  marks::MarksOptions options;
  // --memory-steps, --erosion-passes, --margin (terrain/marks/marks_parameters.h).
  ParameterFlags<marks::MarksOptions> parameters{marks::marks_parameters()};
};

// The snow-depth raster, of the ground's size.
terrain::HeightField read_snow_depth(const MarksCommand& c, const terrain::HeightField& ground) {
  terrain::HeightField depth = terrain::read_raster(c.snow_depth);
  if (depth.width() != ground.width() || depth.height() != ground.height()) {
    throw Error("snow depth '" + c.snow_depth + "' is " + std::to_string(depth.width()) + " x " +
                std::to_string(depth.height()) + " cells but the ground is " +
                std::to_string(ground.width()) + " x " + std::to_string(ground.height()) +
                "; give the depth drift snow fall made on this ground");
  }
  return depth;
}

// One band of material indices: which band of several holds them is not
// guessed (band 1 was read without a word; issue 34, class 6).
void require_single_band(const MarksCommand& c) {
  const int bands = terrain::read_raster_header(c.materials).bands;
  if (bands != 1) {
    throw Error("material raster '" + c.materials + "' has " + std::to_string(bands) +
                " bands; give a single-band raster of material indices (0 sand, 1 mud, 2 snow)");
  }
}

// The --materials raster: per cell 0 sand, 1 mud, 2 snow (the presets' order).
marks::MaterialField read_material_raster(const MarksCommand& c,
                                          const terrain::HeightField& ground) {
  require_single_band(c);
  // Indices, not heights: 1e30 or inf is refused below as no material (it was
  // refused as "a height beyond any ground").
  terrain::ReadOptions indices;
  indices.heights = false;
  const terrain::HeightField m = terrain::read_raster(c.materials, indices);
  if (m.width() != ground.width() || m.height() != ground.height()) {
    throw Error("material raster '" + c.materials + "' is " + std::to_string(m.width()) + " x " +
                std::to_string(m.height()) + " cells but the ground is " +
                std::to_string(ground.width()) + " x " + std::to_string(ground.height()) +
                "; give one value a cell of the ground");
  }
  std::vector<marks::Material> table;
  for (const char* name : {"sand", "mud", "snow"}) table.push_back(*marks::material_preset(name));
  return marks::materials_from_raster(m, table, "material raster '" + c.materials + "'");
}

marks::MaterialField ground_materials(const MarksCommand& c, const TrackFile& track,
                                      const terrain::HeightField& depth,
                                      const terrain::HeightField& ground) {
  if (!c.materials.empty()) return read_material_raster(c, ground);
  marks::Material base = track.material.value_or(*marks::material_preset("sand"));
  if (!c.material.empty()) base = *marks::material_preset(c.material);
  if (depth.empty()) return marks::MaterialField{{base}, {}};
  const marks::Material snow =
      c.material.empty() ? *marks::material_preset("snow") : *marks::material_preset(c.material);
  return marks::materials_from_snow_depth(depth, c.snow_min, base, snow);
}

// The --frames directory, created if missing, before the simulation.
void make_frames_directory(const std::string& frames) {
  std::error_code ec;
  if (fs::exists(frames, ec) && !fs::is_directory(frames, ec))
    throw Error("--frames '" + frames +
                "' is not a directory; name a directory (it is created if missing)");
  fs::create_directories(frames, ec);
  if (ec) throw Error("cannot create the --frames directory '" + frames + "': " + ec.message());
}

// Issue 32: an object that never touches the ground (a typo in a height) is
// named with how near it came, instead of a silent run with no marks.
void warn_about_misses(const marks::MarksReport& report) {
  for (const marks::ObjectReport& o : report.objects) {
    if (o.contact_steps > 0) continue;
    if (!std::isfinite(o.clearance)) {
      std::fprintf(stderr,
                   "drift marks: warning: %s is never over the ground (its footprint misses the "
                   "raster in all its %d steps); check its keyframes' x and y\n",
                   o.name.c_str(), o.steps);
      continue;
    }
    std::fprintf(stderr,
                 "drift marks: warning: %s never touches the ground: its lowest point comes no "
                 "nearer than %.4g m above the ground beneath it (bottom at %.6g m, ground at "
                 "%.6g m); check its keyframes' z (absolute unless follow_ground = true)\n",
                 o.name.c_str(), o.clearance, o.bottom, o.ground);
  }
}

// What a run wrote (the non-empty paths of `written`), the objects that never
// touched the ground, and its volumes; `tail` adds the block-by-block run's
// figures to the summary line.
void report_run(const std::vector<std::string>& written, const marks::MarksReport& report,
                const std::string& tail) {
  for (const std::string& path : written)
    if (!path.empty()) std::printf("marks: wrote %s\n", path.c_str());
  warn_about_misses(report);
  std::printf(
      "marks: %d steps, %d with contact; %.6g m3 under objects: %.6g displaced, %.6g compressed "
      "away%s\n",
      report.steps, report.contact_steps, report.collided, report.displaced, report.compressed,
      tail.c_str());
}

// --block: the ground read, marked and written a block at a time (issue 36
// item 3), for rasters larger than memory.
void run_marks_by_blocks(MarksCommand& c, const CLI::App& sub) {
  // Frames are the whole field after every step, and a block's window holds
  // the whole track's steps at once: a frame would need every block at that
  // step (all of them in memory, or every block rerun per frame). --posed
  // places objects that follow the ground on heights read from the whole
  // raster at one time; it is not refused for a reason of principle, but the
  // mesh does not depend on the blocks: make it with a run without --block
  // (or on a crop that holds the objects).
  if (!c.frames.empty())
    usage_error(
        "--frames writes the whole field after every step, and --block works a window through "
        "the whole track at a time, so no step's field is ever whole; drop --block for frames "
        "(crop the ground around the track with drift import --crop if it does not fit)");
  if (!c.posed.empty())
    usage_error(
        "--posed is not made block by block; run drift marks --posed without --block on the "
        "same track (a crop of the ground around the objects gives the same mesh)");
  if (c.add_snow)
    usage_error(
        "--add-snow is not made block by block; lay the snow on the ground first (GROUND + "
        "depth) and give that surface as the ground, with --snow-depth for the materials");
  if (!c.materials.empty() && (!c.snow_depth.empty() || !c.material.empty()))
    usage_error("--materials gives every cell its material; drop --snow-depth and --material");
  c.parameters.apply(sub, c.options);
  if (!c.materials.empty()) require_single_band(c);
  std::vector<fs::path> inputs = {c.ground, c.track, c.snow_depth, c.materials};
  for (const fs::path& mesh : object_mesh_paths(c.track, "track file")) inputs.push_back(mesh);
  OutputSet outputs({c.output, c.disturbed}, inputs);
  TrackFile track = read_track_file(c.track);
  marks::MarksOptions o = c.options;
  o.step = track.step;
  o.camera = track.camera;
  o.renderer = c.renderer == "opengl" ? marks::BottomRenderer::OpenGL : marks::BottomRenderer::Cpu;
  if (!c.material.empty())
    for (marks::MarkObject& obj : track.objects) obj.material.reset();  // --material overrides all
  marks::Material base = track.material.value_or(*marks::material_preset("sand"));
  if (!c.material.empty()) base = *marks::material_preset(c.material);
  require_metric_crs(terrain::HeightField(1, 1, 0.0f, terrain::read_raster_header(c.ground).geo),
                     c.ground);
  marks::MarksBlockFiles files;
  files.ground = c.ground, files.output = c.output, files.disturbed = c.disturbed;
  files.block = c.block, files.halo = c.halo;
  files.materials = c.materials, files.snow_depth = c.snow_depth, files.snow_min = c.snow_min;
  if (!c.material.empty()) files.snow = *marks::material_preset(c.material);  // as one pass
  const marks::MarksBlockReport r =
      marks::marks_to_files(files, track.objects, base, o, terminal_progress("marks"));
  outputs.commit();
  char blocks[160];
  std::snprintf(blocks, sizeof blocks,
                "; %d of %d blocks of %d cells worked, halo %d cells (%d widened, widest %d)",
                r.simulated, r.blocks, r.block, r.halo, r.widened, r.largest_halo);
  report_run({c.output, c.disturbed}, r.report, blocks);
}

void run_marks(MarksCommand& c, const CLI::App& sub) {
  if (c.block > 0) return run_marks_by_blocks(c, sub);
  // The halo is a block's: refused without blocks, not ignored (issue 34).
  if (sub.count("--halo") > 0)
    usage_error("--halo applies to --block only; add --block N, or drop --halo");
  if (c.add_snow && c.snow_depth.empty()) usage_error("--add-snow needs --snow-depth");
  if (!c.materials.empty() && (!c.snow_depth.empty() || !c.material.empty()))
    usage_error("--materials gives every cell its material; drop --snow-depth and --material");
  c.parameters.apply(sub, c.options);
  // Frames are each complete when written (they come one by one); the marked
  // ground and the disturbed raster replace their files together at the end.
  std::vector<fs::path> inputs = {c.ground, c.track, c.snow_depth, c.materials};
  for (const fs::path& mesh : object_mesh_paths(c.track, "track file")) inputs.push_back(mesh);
  OutputSet outputs({c.output, c.disturbed, c.posed}, inputs);
  std::vector<fs::path> named = inputs;
  named.insert(named.end(), {c.output, c.disturbed, c.posed});
  // (--disturbed fr/frame_00001.tif beside --frames fr kept one of the two.)
  refuse_files_among_frames("--frames", c.frames, "frame_", ".tif", named);
  TrackFile track = read_track_file(c.track);
  marks::MarksOptions o = c.options;
  o.step = track.step;
  o.camera = track.camera;
  o.renderer = c.renderer == "opengl" ? marks::BottomRenderer::OpenGL : marks::BottomRenderer::Cpu;
  o.track_disturbed = !c.disturbed.empty();
  if (!c.material.empty())
    for (marks::MarkObject& obj : track.objects) obj.material.reset();  // --material overrides all
  terrain::HeightField ground = terrain::read_raster(c.ground);
  require_metric_crs(ground, c.ground);
  terrain::HeightField depth;
  if (!c.snow_depth.empty()) depth = read_snow_depth(c, ground);
  // Mark the snow surface: ground + depth.
  if (c.add_snow) ground = terrain::lay_on_ground(ground, depth, "the snow depth");
  marks::MaterialField materials = ground_materials(c, track, depth, ground);
  if (!c.frames.empty()) make_frames_directory(c.frames);
  marks::StepFn on_step;
  if (!c.frames.empty()) {
    on_step = [&](int step, const marks::MarksSimulation& sim) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05d.tif", step);
      terrain::write_geotiff(sim.heights_as_float(), fs::path(c.frames) / name,
                             {"ground height with marks (m)", "m"});
      return true;
    };
  }
  const marks::MarksResult r = marks::simulate_marks(ground, track.objects, std::move(materials), o,
                                                     on_step, terminal_progress("marks"));
  terrain::write_geotiff(r.heights, c.output, {"ground height with marks (m)", "m"});
  if (!c.disturbed.empty()) {
    terrain::write_geotiff(r.disturbed, c.disturbed,
                           {"ground disturbed by marks (m compressed, displaced or slid)", "m"});
  }
  if (!c.posed.empty()) {  // issue 32 item 7: the objects where they stand at --posed-at
    const double t = c.posed_at.value_or(marks::run_end(track.objects));
    const terrain::Mesh posed = marks::posed_objects(track.objects, ground, t);
    if (terrain::is_mesh_output(c.posed))  // .glb/.gltf/.fbx/.stl/.ply by extension
      terrain::write_mesh(posed, c.posed);
    else
      terrain::write_obj(posed, c.posed);
  }
  outputs.commit();
  report_run({c.output, c.disturbed, c.posed}, r.report, "");
}

}  // namespace

void marks_flags(CLI::App* sub, MarksCommand* c) {
  sub->add_option("ground", c->ground,
                  "ground heights, a metric GeoTIFF (DEM, dunes, snow surface)")
      ->required();
  sub->add_option("--track", c->track,
                  "TOML track file: step, material, [[objects]] with keyframes")
      ->required();
  sub->add_option("-o,--output", c->output, "ground with the marks, GeoTIFF (m)")->required();
  sub->add_option("--material", c->material, "overrides every material: sand, mud or snow")
      ->check(CLI::IsMember({"sand", "mud", "snow"}));
  sub->add_option("--disturbed", c->disturbed,
                  "GeoTIFF of how much each cell was compressed, displaced or slid (m)");
  sub->add_option("--frames", c->frames,
                  "directory for the field after every step (frame_NNNNN.tif)");
  sub->add_option("--snow-depth", c->snow_depth,
                  "snow depth GeoTIFF (drift snow fall): snow where it lies, the ground's material "
                  "elsewhere");
  sub->add_option("--materials", c->materials,
                  "GeoTIFF of the ground's material per cell: 0 sand, 1 mud, 2 snow (painted or "
                  "derived; objects' materials still apply where they walk)");
  sub->add_flag("--add-snow", c->add_snow,
                "mark the snow surface: GROUND + the --snow-depth raster (the output is that "
                "surface with the marks)");
  sub->add_option("--snow-min", c->snow_min,
                  "snow shallower than this (m) leaves the ground's material")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  sub->add_option("--posed", c->posed,
                  "mesh (OBJ; .glb, .gltf, .fbx, .stl, .ply by extension) of the objects at their "
                  "pose at --posed-at (same keyframes as the marks), "
                  "in the ground's CRS from the raster's north-west corner: a scene's [[objects]] "
                  "mesh, at position = that corner ([0, 0, 0] on a local grid)");
  sub->add_option("--posed-at", c->posed_at,
                  "time (s) of the --posed objects; default: the run's last keyframe")
      ->check(CLI::Range(-1e9, 1e9));
  sub->add_option("--block", c->block,
                  "work block by block on blocks of N cells a side (rounded up to a multiple of "
                  "4), reading and writing the rasters a block at a time: grounds larger than "
                  "memory (0: the whole raster at once)")
      ->check(CLI::Range(0, 1 << 20));
  add_halo_option(*sub, c->halo,
                  "with --block: cells around a block that its window also works (doubled where "
                  "marks reach the window's edge)");
  c->parameters.add_to(*sub);
  sub->add_option("--seed", c->options.seed,
                  "seed of the roughness draws (sigma, paper 000, 3.5); same seed, same marks")
      ->capture_default_str();
  add_choice(*sub, "--renderer", c->renderer, {"cpu", "opengl"},
             "how the object's bottom is rendered: cpu (z-buffer, faster at these sizes) or "
             "opengl (OSMesa)");
}

DRIFT_COMMAND(
    50, "marks",
    "marks of objects in soft ground: footprints, tyre tracks, dragged objects in sand, mud "
    "and snow (paper 000)",
    marks_flags, run_marks);

}  // namespace drift::pipeline
