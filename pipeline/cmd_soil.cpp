// drift soil SCENARIO.toml -o OUT.ply: voxel soil that pours, slides, piles
// and is pushed, dug and lifted (paper 004, terrain/soil/simulation.h).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/cli.h"
#include "pipeline/parameter_flags.h"
#include "pipeline/progress_bar.h"
#include "pipeline/soil_scenario_file.h"
#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/mesh_io.h"
#include "terrain/output_set.h"
#include "terrain/raster_io.h"
#include "terrain/soil/soil_parameters.h"
#include "terrain/soil/soil_surface.h"
#include "terrain/soil/top_surface.h"

namespace drift::pipeline {

namespace {

namespace fs = std::filesystem;

struct SoilCommand {
  std::string scenario, output, vdb, surface, collision, frames, vdb_frames, soil_type, terrain,
      ground;
  int ground_margin = 32;
  int steps = -1, frame_every = 10;
  // --phi, --cohesion, --gamma, --moisture (terrain/soil/soil_parameters.h):
  // those given override the scenario's soil.
  ParameterFlags<soil::SoilOptions> parameters{soil::soil_parameters()};
  bool no_ridge_fix = false;
};

void check_mesh_path(const std::string& path, const char* flag) {
  if (!terrain::is_mesh_output(path))
    usage_error(std::string(flag) + " '" + path +
                "' must end in .ply, .obj, .glb, .gltf, .stl or .fbx");
}

// The command line's values over the scenario's own.
// A preset (--soil) first, then the single values over it.
void apply_overrides(const SoilCommand& c, const CLI::App& sub, soil::SoilScenario& sc) {
  if (c.steps >= 0) sc.steps = c.steps;
  if (!c.soil_type.empty()) sc.options.soil = soil::soil_preset(c.soil_type);
  c.parameters.apply(sub, sc.options);
  validate_flags([&sc] { sc.options.validate(); }, c.parameters.flag_names());
}

// Writes every product (into the OutputSet's temporary files); returns what to
// report once they are committed, so "wrote" is never printed for a file that a
// later failure leaves unreplaced.
std::vector<std::string> write_products(const SoilCommand& c, const soil::SoilScenario& sc,
                                        const soil::SoilState& state,
                                        const soil::SurfaceOptions& surface) {
  std::vector<std::string> wrote;
  const terrain::Mesh mesh = soil::soil_surface(state, surface);
  if (mesh.triangles.empty()) throw Error("scenario '" + c.scenario + "' left no soil surface");
  terrain::write_mesh(mesh, c.output);  // by extension (terrain/mesh_io.h)
  wrote.push_back(c.output + " (" + std::to_string(mesh.triangle_count()) + " triangles)");
  if (!c.collision.empty()) {
    const terrain::Mesh bodies = soil::iso_surface(state.shape, state.psi);
    if (bodies.triangles.empty()) throw Error("--collision: the scenario has no terrain or bodies");
    terrain::write_mesh(bodies, c.collision);
    wrote.push_back(c.collision + " (" + std::to_string(bodies.triangle_count()) + " triangles)");
  }
  if (!c.vdb.empty()) {
    soil::write_density_vdb(state, c.vdb);
    wrote.push_back(c.vdb + " (grids density, collision, wetness, velocity)");
  }
  if (!c.surface.empty()) {
    terrain::HeightField top = soil::top_surface(
        state, sc.geo.crs_wkt.empty() && sc.terrain.kind != soil::TerrainSource::Kind::HeightField
                   ? terrain::local_georeference(sc.shape.voxel_size)
                   : sc.geo);
    terrain::write_geotiff(top, c.surface, {"top of soil and ground (m)", "m"});
    wrote.push_back(c.surface);
  }
  if (!c.ground.empty()) {
    terrain::write_geotiff(soil::ground_raster(sc.shape, sc.terrain.heights, c.ground_margin),
                           c.ground, {"ground under the soil (m)", "m"});
    wrote.push_back(c.ground);
  }
  return wrote;
}

void run_soil(SoilCommand& c, const CLI::App& sub) {
  check_mesh_path(c.output, "-o");
  if (!c.collision.empty()) check_mesh_path(c.collision, "--collision");
  if (c.frame_every < 1) usage_error("--frame-every must be at least 1");
  soil::SoilScenario sc = read_soil_scenario(c.scenario, c.terrain);
  apply_overrides(c, sub, sc);
  if (!c.ground.empty()) {  // --ground's raster, checked before the simulation
    const std::uint64_t w = sc.shape.nx + 2ull * c.ground_margin,
                        h = sc.shape.ny + 2ull * c.ground_margin;
    require_memory(w * h * sizeof(float),
                   "--ground raster of " + std::to_string(w) + " x " + std::to_string(h) + " cells",
                   "lower --ground-margin");
  }
  for (const auto& [flag, dir] :
       {std::pair{"--frames", &c.frames}, std::pair{"--vdb-frames", &c.vdb_frames}}) {
    if (dir->empty() || fs::is_directory(*dir)) continue;
    throw Error(std::string(flag) + " directory '" + *dir + "' " +
                (fs::exists(*dir) ? "is not a directory; name a directory"
                                  : "does not exist; create it first"));
  }

  // Frames are each complete when written; the products replace their files
  // together at the end (docs/outputs.md).
  // The scenario's DEM is an input too, unless --terrain replaces it.
  const fs::path dem = c.terrain.empty() ? soil_scenario_dem(c.scenario) : fs::path(c.terrain);
  OutputSet outputs({c.output, c.collision, c.vdb, c.surface, c.ground}, {c.scenario, dem});
  const std::vector<fs::path> named = {c.output, c.collision, c.vdb, c.surface,
                                       c.ground, c.scenario,  dem};
  refuse_files_among_frames("--frames", c.frames, "frame_", ".ply", named);
  refuse_files_among_frames("--vdb-frames", c.vdb_frames, "soil_", ".vdb", named);
  soil::SoilSimulation sim = soil::make_simulation(sc);  // checks sizes and memory first
  const soil::SurfaceOptions surface{
      c.no_ridge_fix ? soil::RidgeFix::Off : soil::RidgeFix::StraightSlopes, 3, 0.0};
  soil::SoilRunOptions run;
  run.steps = sc.steps;
  // Mesh frames re-extract only what changed since the last (issue 33).
  soil::SurfaceExtractor frames(surface);
  if (!c.frames.empty() || !c.vdb_frames.empty()) {
    run.frame_every = c.frame_every;
    run.frame = [&](const soil::SoilSimulation& s, int step) {
      char name[32];
      if (!c.frames.empty()) {
        std::snprintf(name, sizeof name, "frame_%05d.ply", step);
        terrain::write_mesh(frames.extract(s.state()), fs::path(c.frames) / name);
      }
      if (!c.vdb_frames.empty()) {  // soil_00010.vdb, ...: a volume sequence
        std::snprintf(name, sizeof name, "soil_%05d.vdb", step);
        soil::write_density_vdb(s.state(), fs::path(c.vdb_frames) / name);
      }
    };
  }
  const soil::SoilRunStats stats = soil::run_soil(sim, run, terminal_progress("soil"));

  const std::vector<std::string> wrote = write_products(c, sc, sim.state(), surface);
  outputs.commit();
  for (const std::string& line : wrote) std::printf("soil: wrote %s\n", line.c_str());
  const double mass0 = stats.mass_before, mass1 = stats.mass_after;
  std::printf(
      "soil: %d steps of %dx%dx%d voxels (%.3g m) in %.2f s (%.1f steps/s); soil %.6g -> "
      "%.6g voxels (relative change %.2g)\n",
      sc.steps, sc.shape.nx, sc.shape.ny, sc.shape.nz, sc.shape.voxel_size, stats.seconds,
      sc.steps / std::max(stats.seconds, 1e-9), mass0, mass1,
      mass0 > 0 ? (mass1 - mass0) / mass0 : 0.0);
}

}  // namespace

void soil_flags(CLI::App* sub, SoilCommand* c) {
  sub->add_option("scenario", c->scenario, "scenario TOML (see data/soil/, docs/soil.md)")
      ->required();
  sub->add_option("-o,--output", c->output, "soil surface mesh, .ply or .obj (metres)")->required();
  sub->add_option("--terrain", c->terrain,
                  "metric GeoTIFF replacing the dem the scenario's [terrain] names");
  whole_in_range(sub->add_option("--steps", c->steps, "time steps (overrides the scenario's)"), 0,
                 soil::SoilScenario::kMaxSteps);
  sub->add_option("--soil", c->soil_type, "soil type of the thesis's table 6")
      ->check(CLI::IsMember({"dry_sand", "sandy_loam", "loam"}));
  c->parameters.add_to(*sub);
  sub->add_option("--frames", c->frames, "directory for a surface mesh every --frame-every steps");
  sub->add_option("--vdb-frames", c->vdb_frames,
                  "directory for an OpenVDB file (density, collision, wetness, velocity) every "
                  "--frame-every steps, soil_NNNNN.vdb: a volume sequence for Blender, Houdini");
  whole_in_range(sub->add_option("--frame-every", c->frame_every, "steps between frames"), 1,
                 std::numeric_limits<int>::max())
      ->capture_default_str();
  sub->add_option("--vdb", c->vdb,
                  "OpenVDB file of the density, collision, wetness and velocity grids");
  sub->add_option("--surface", c->surface,
                  "GeoTIFF of the top of the soil and what it rests on (m), georeferenced");
  sub->add_option("--collision", c->collision, "mesh of the terrain and bodies (iso-0.5 of psi)");
  sub->add_option("--ground", c->ground,
                  "GeoTIFF of the ground under the soil (terrain or the grid's floor), widened by "
                  "--ground-margin columns, in the meshes' frame: a terrain to render them on");
  whole_in_range(
      sub->add_option("--ground-margin", c->ground_margin, "columns added around the grid"), 0,
      100000)
      ->capture_default_str();
  sub->add_flag("--no-ridge-fix", c->no_ridge_fix,
                "extract the raw density (shows the thesis's vertical ridges)");
}

DRIFT_COMMAND(60, "soil",
              "voxel soil that pours, slides, piles and is pushed, dug and "
              "lifted; writes its surface (paper 004; docs/soil.md)",
              soil_flags, run_soil);

}  // namespace drift::pipeline
