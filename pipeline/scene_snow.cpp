// [snow]: the products of drift snow cover and drift snow fall in a scene. A
// material mask for the snow material (cover), a height change that is also
// the snow's thickness (depth), and the snowy objects, an attributed mesh of
// the declared form terrain::products::kSnowyObjects (objects).
#include "pipeline/scene_products.h"
#include "render/material.h"
#include "terrain/error.h"
#include "terrain/mesh_io.h"
#include "terrain/products.h"

namespace drift::pipeline {

namespace {

namespace products = terrain::products;

// Replaces the scene's objects by their snowy versions: the same objects in
// the same order, raised by their snow, keeping their colours, each with its
// per-vertex snow attributes (the renderer shades by kSnowCoverage).
void place_snowy_objects(SceneFile& scene, const std::filesystem::path& file) {
  std::vector<terrain::PlacedMesh>& meshes = scene.input.meshes;
  std::vector<terrain::Mesh> parts =
      products::split_objects(terrain::read_ply(file), products::kSnowyObjects, file);
  if (parts.size() != meshes.size()) {
    throw Error("'" + file.string() + "' holds " + std::to_string(parts.size()) +
                " objects but the scene has " + std::to_string(meshes.size()) +
                "; give the scene the objects file drift snow fall was given");
  }
  for (std::size_t o = 0; o < parts.size(); ++o) {
    meshes[o].position = parts[o].origin;
    meshes[o].mesh = std::move(parts[o]);
  }
}

void load_snow(SceneFile& scene) {
  render::TerrainSurface& surface = scene.input.surface;
  if (const auto objects = scene.product_file("snow.objects"); !objects.empty())
    place_snowy_objects(scene, objects);
  if (const auto cover = scene.product_file("snow.cover"); !cover.empty())
    surface.snow_cover = read_metric_raster(cover);
  if (const auto depth = scene.product_file("snow.depth"); !depth.empty()) {
    // The snow's depth both raises the surface and sets its translucency.
    surface.snow_depth = read_metric_raster(depth);
    scene.input.height_changes.push_back({"snow depth", *surface.snow_depth});
  }
}

// The snow's look; its products load whether or not the scene has [snow]
// (the flags may give them).
SceneFile::Loader read_snow(Section& snow, SceneFile& scene) {
  render::TerrainSurface& surface = scene.input.surface;
  surface.snow.albedo = snow.color("color", surface.snow.albedo);
  surface.snow.roughness = static_cast<float>(
      snow.number("roughness", surface.snow.roughness, 0.0, render::kMaxRoughness));
  surface.snow.forward_scattering = static_cast<float>(
      snow.number("forward_scattering", surface.snow.forward_scattering, 0.0, 1.0));
  surface.snow_scattering =
      static_cast<float>(snow.number("scattering", surface.snow_scattering, 1.0, 1e5));
  surface.snow_cover_outside =
      static_cast<float>(snow.number("cover_outside", surface.snow_cover_outside, 0.0, 1.0));
  return load_snow;
}

}  // namespace

StageSection snow_section() {
  return {"snow",
          {{"cover", "--snow-cover", "snow cover raster"},
           {"depth", "--snow-depth", "snow depth raster"},
           {"objects", "--snow-objects", "snowy objects from drift snow fall --mesh-out"}},
          read_snow};
}

}  // namespace drift::pipeline
