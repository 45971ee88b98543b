// drift snow fall GROUND.tif -o DEPTH.tif: snowfall with occlusion by the
// ground and objects, irregular motion and stabilisation (paper 003, snow/snowfall.h).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <memory>

#include "pipeline/cli.h"
#include "pipeline/object_list.h"
#include "pipeline/parameter_flags.h"
#include "pipeline/progress_bar.h"
#include "snow/snowfall.h"
#include "snow/snowfall_blocks.h"
#include "snow/snowfall_parameters.h"
#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/height_change.h"
#include "terrain/mesh_io.h"
#include "terrain/output_set.h"
#include "terrain/products.h"
#include "terrain/raster_blocks.h"
#include "terrain/raster_io.h"

namespace drift::pipeline {

namespace {

struct SnowfallCommand {
  std::string ground, objects, output, cover, surface, mesh_out;
  std::vector<double> direction{snow::SnowfallOptions{}.azimuth_deg,
                                snow::SnowfallOptions{}.elevation_deg};
  std::string occlusion = "sweep";
  std::string stabilise = "passes";
  int block = 0;
  int halo = snow::SnowfallBlockFiles{}.halo;
  unsigned long long seed = snow::SnowfallOptions{}.seed;
  // The table's flags (snow/snowfall_parameters.h); only those given override
  // SnowfallOptions{}'s defaults.
  ParameterFlags<snow::SnowfallOptions> parameters{snow::snowfall_parameters()};
};

// --mesh-out's help from the declared form it writes (terrain/products.h).
std::string mesh_out_help() {
  std::string help = "PLY of the objects raised by their snow, with per-vertex";
  const auto& names = terrain::products::kSnowyObjects.attributes;
  for (std::size_t i = 0; i < names.size(); ++i) help += (i ? ", " : " ") + std::string(names[i]);
  return help;
}

// --direction's help from the table's rows for its two parts.
std::string direction_help() {
  std::string help = "AZ,EL where the snow comes from, like a sun position (0,90: straight down)";
  for (const snow::SnowfallParameter& p : snow::snowfall_parameters())
    if (std::string(p.flag).rfind("--direction ", 0) == 0)
      help += std::string("; ") + (p.flag + 12) + " in " + p.range();
  return help;
}

// --block with --stabilise direct: the ground read, settled and written block
// by block through GDAL (snow/snowfall_blocks.h), the rasters of one pass.
void run_snowfall_in_blocks(const SnowfallCommand& c, const snow::SnowfallOptions& o,
                            OutputSet& outputs) {
  {
    const terrain::RasterBlockReader reader(c.ground);
    if (terrain::is_geographic(reader.geo().crs_wkt))
      throw Error("raster '" + c.ground +
                  "' is in degrees (geographic CRS); convert it to metres first: drift import " +
                  c.ground + " -o DEM_metric.tif");
  }
  snow::SnowfallBlockReport r;
  naming_input(c.ground, [&] {
    r = snow::snowfall_to_files({c.ground, c.output, c.cover, c.surface, o.block, c.halo}, o,
                                terminal_progress("snow fall"));
  });
  outputs.commit();
  std::printf("snow fall: wrote %s\n", c.output.c_str());
  if (!c.cover.empty()) std::printf("snow fall: wrote %s\n", c.cover.c_str());
  if (!c.surface.empty()) std::printf("snow fall: wrote %s\n", c.surface.c_str());
  std::printf("snow fall: %.6g m3 fell on the ground, %.6g on it after settling\n", r.fallen_volume,
              r.ground_volume);
  std::printf(
      "snow fall: %d blocks of %d cells, occlusion halo %d cells, stabilisation halo up to %d "
      "cells (%d of the %d windows worked again wider, %d times in all)%s\n",
      r.blocks, r.block, r.occlusion_halo, r.largest_halo, r.windows_widened, r.blocks, r.widened,
      r.converged ? "" : " (NOT at rest within the tolerance)");
}

void run_snowfall(SnowfallCommand& c, const CLI::App& sub) {
  if (c.direction.size() != 2) usage_error("--direction takes AZ,EL (degrees)");
  snow::SnowfallOptions o;
  c.parameters.apply(sub, o);
  o.azimuth_deg = c.direction[0];
  o.elevation_deg = c.direction[1];
  o.seed = c.seed;
  o.occlusion.terrain =
      c.occlusion == "opengl" ? snow::TerrainOcclusion::OpenGL : snow::TerrainOcclusion::Sweep;
  o.direct_stabilise = c.stabilise == "direct";
  // Each stabilisation's own setting is refused with the other, not ignored
  // (issue 34: no value dropped silently).
  if (!o.direct_stabilise && sub.count("--direct-layers") > 0)
    usage_error(
        "--direct-layers applies to --stabilise direct only; add --stabilise direct, or "
        "drop --direct-layers");
  if (o.direct_stabilise && sub.count("--coarse-levels") > 0)
    usage_error(
        "--coarse-levels applies to --stabilise passes only; drop --coarse-levels, or "
        "use --stabilise passes");
  if (c.block < 0) usage_error("--block takes a number of cells, 0 or more");
  // Blocks tile the ground's horizon sweep only: refused, not ignored, with
  // the objects' depth maps or OSMesa's (issue 34: no value dropped silently).
  if (c.block > 0 && (!c.objects.empty() || c.occlusion == "opengl"))
    usage_error(
        "--block works on the ground alone with --occlusion sweep; drop --block, or "
        "--objects and --occlusion opengl");
  o.block = c.block;
  if (sub.count("--halo") && !(c.block > 0 && o.direct_stabilise))
    usage_error("--halo works with --block and --stabilise direct; drop --halo or add them");
  if (!c.mesh_out.empty() && c.objects.empty())
    usage_error("--mesh-out needs --objects (there are no objects to write)");
  // Before reading anything large; the ranges live in SnowfallOptions::validate().
  validate_flags([&o] { o.validate(); }, c.parameters.flag_names());

  std::vector<std::filesystem::path> inputs = {c.ground, c.objects};
  if (!c.objects.empty()) {  // the meshes are inputs too: --mesh-out must not replace one
    for (const auto& mesh : object_mesh_paths(c.objects, "objects file")) inputs.push_back(mesh);
  }
  OutputSet outputs({c.output, c.cover, c.surface, c.mesh_out}, inputs);
  if (o.block > 0 && o.direct_stabilise) {
    run_snowfall_in_blocks(c, o, outputs);
    return;
  }
  const terrain::HeightField ground = terrain::read_raster(c.ground);
  require_metric_crs(ground, c.ground);
  const std::vector<terrain::PlacedMesh> objects =
      c.objects.empty() ? std::vector<terrain::PlacedMesh>{} : read_objects_file(c.objects);
  const snow::SnowfallResult r =
      snow::simulate_snowfall(ground, objects, o, terminal_progress("snow fall"));

  terrain::write_geotiff(r.depth, c.output, {"snow depth (m)", "m"});
  if (!c.cover.empty()) terrain::write_geotiff(r.coverage, c.cover, {"snow coverage (0..1)", ""});
  if (!c.surface.empty())
    terrain::write_geotiff(terrain::lay_on_ground(ground, r.depth, "the snow depth"), c.surface,
                           {"snow surface height, ground + depth (m)", "m"});
  if (!c.mesh_out.empty()) {  // .glb/.gltf/.obj/.stl/.fbx by extension, else PLY as before
    if (terrain::is_mesh_output(c.mesh_out))
      terrain::write_mesh(r.objects, c.mesh_out);
    else
      terrain::write_ply(r.objects, c.mesh_out);
  }
  outputs.commit();
  std::printf("snow fall: wrote %s\n", c.output.c_str());
  if (!c.cover.empty()) std::printf("snow fall: wrote %s\n", c.cover.c_str());
  if (!c.surface.empty()) std::printf("snow fall: wrote %s\n", c.surface.c_str());
  if (!c.mesh_out.empty()) {
    std::printf("snow fall: wrote %s (%zu triangles; place it at position = [%.0f, %.0f, 0])\n",
                c.mesh_out.c_str(), r.objects.triangle_count(), r.mesh_origin.x(),
                r.mesh_origin.y());
  }
  std::printf(
      "snow fall: %.6g m3 fell: %.6g on the ground, %.6g on objects, %.6g shed by objects onto "
      "the ground, %.6g off the raster\n",
      r.fallen_volume, r.ground_volume, r.object_volume, r.shed_volume, r.lost_volume);
  std::printf("snow fall: stabilised in %d passes on the ground, %d on objects%s\n",
              r.ground_iterations, r.object_iterations,
              r.converged ? "" : " (NOT converged: raise --max-iterations)");
}

}  // namespace

void snowfall_flags(CLI::App* sub, SnowfallCommand* c) {
  sub->add_option("ground", c->ground, "ground heights, a metric GeoTIFF (see drift import)")
      ->required();
  sub->add_option("--objects", c->objects, "TOML file of [[objects]] (mesh, position, ...)");
  sub->add_option("-o,--output", c->output, "snow depth GeoTIFF (m)")->required();
  sub->add_option("--cover", c->cover, "snow coverage GeoTIFF (0..1)");
  sub->add_option("--surface", c->surface,
                  "snow surface GeoTIFF: ground + snow depth (m), e.g. for drift marks");
  sub->add_option("--mesh-out", c->mesh_out, mesh_out_help());
  sub->add_option("--direction", c->direction, direction_help())
      ->expected(2)
      ->delimiter(',')
      ->capture_default_str();
  add_choice(*sub, "--occlusion", c->occlusion, {"sweep", "opengl"},
             "how the ground occludes: sweep (horizon sweep) or opengl (OSMesa depth map)");
  add_choice(*sub, "--stabilise", c->stabilise, {"passes", "direct"},
             "how the ground's snow comes to rest: passes (paper 003's rule, many passes) "
             "or direct (in one step, near-linear cost; docs/snowfall.md)");
  sub->add_option("--block", c->block,
                  "sweep the ground's occlusion on blocks of N cells a side with their halo "
                  "(the same result; ground without objects, --occlusion sweep); with "
                  "--stabilise direct the snow is also settled, read and written block by "
                  "block (rasters larger than memory); 0: one pass")
      ->capture_default_str();
  add_halo_option(*sub, c->halo,
                  "with --block and --stabilise direct: cells around a block that its window "
                  "also settles (doubled where snow moves near the window's edge)");
  c->parameters.add_to(*sub);
  add_seed_option(*sub, c->seed);
}

DRIFT_COMMAND(41, "fall",
              "snowfall on a DEM and objects: occlusion by depth maps, jittered directions, "
              "stabilisation (paper 003)",
              snowfall_flags, run_snowfall, "snow", "snow: snowfall (fall) and snow cover (cover)");

}  // namespace drift::pipeline
