// [snow]: the products of drift snow cover and drift snow fall in a scene. A
// material mask for the snow material (cover), a height change that is also
// the snow's thickness (depth), and the snowy objects, an attributed mesh of
// the declared form terrain::products::kSnowyObjects (objects).
#include <cctype>
#include <optional>

#include "pipeline/scene_products.h"
#include "render/material.h"
#include "render/surface.h"
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
  // Any mesh format, as every object is read; but only PLY and GLB carry the
  // per-vertex snow back: Assimp drops glTF's custom attributes (assimp#4830),
  // so a GLB is read by drift's own reader (terrain::read_glb), and the other
  // formats, which have none, are refused naming the fix.
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const terrain::Mesh snowy = ext == ".glb" ? terrain::read_glb(file) : terrain::read_mesh(file);
  if (ext != ".ply" && !snowy.attribute(products::kSnowCoverage)) {
    throw Error(
        "'" + file.string() + "' has no per-vertex snow: only PLY and GLB keep drift's " +
        "attributes when read (Assimp drops glTF's custom attributes); give --snow-objects " +
        "([snow] objects) the PLY or GLB of drift snow fall --mesh-out OBJECTS.ply");
  }
  std::vector<terrain::Mesh> parts = products::split_objects(snowy, products::kSnowyObjects, file);
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

// The snow's look, from [snow]'s keys.
struct SnowLook {
  render::Material material = *render::material_preset("snow");
  // Kubelka-Munk scattering coefficient of the snowpack, per metre
  // (render::LayerThickness); [snow] scattering overrides fresh snow's.
  float scattering = render::kFreshSnowScattering;
  float cover_outside = 0.0f;  // the cover beyond its raster (a cropped snowfall)
};

// Snow cover as a material mask of the snow material, laid last over the
// ground's layers; with a depth it is translucent where thin, and it buries
// normal details (ripples).
render::MaterialLayer snow_layer(const SnowLook& look, terrain::HeightField cover,
                                 const std::optional<terrain::HeightField>& depth) {
  render::MaterialLayer layer;
  layer.name = "snow";
  layer.material = render::full_override(look.material);
  layer.mask = std::move(cover);
  layer.outside = look.cover_outside;
  layer.flakes = true;  // thin snow and stuck flakes (paper 003, 2.1(4))
  if (depth) layer.thickness = render::LayerThickness{*depth, look.scattering};
  layer.buries_details = true;
  return layer;
}

void load_snow(SceneFile& scene, const SnowLook& look) {
  if (const auto objects = scene.product_file("snow.objects"); !objects.empty())
    place_snowy_objects(scene, objects);
  std::optional<terrain::HeightField> depth;
  if (const auto file = scene.product_file("snow.depth"); !file.empty()) {
    // The snow's depth both raises the surface and sets its translucency.
    depth = read_metric_raster(file);
    scene.input.height_changes.push_back({"snow depth", *depth});
  }
  if (const auto cover = scene.product_file("snow.cover"); !cover.empty())
    scene.input.surface.layers.push_back(snow_layer(look, read_metric_raster(cover), depth));
}

// The snow's look; its products load whether or not the scene has [snow]
// (the flags may give them). Objects whose meshes carry snow coverage take
// the snow material whatever the scene gives.
SceneFile::Loader read_snow(Section& snow, SceneFile& scene) {
  SnowLook look;
  render::Material& m = look.material;
  m.albedo = snow.color("color", m.albedo);
  m.roughness =
      static_cast<float>(snow.number("roughness", m.roughness, 0.0, render::kMaxRoughness));
  m.forward_scattering =
      static_cast<float>(snow.number("forward_scattering", m.forward_scattering, 0.0, 1.0));
  look.scattering = static_cast<float>(snow.number("scattering", look.scattering, 1.0, 1e5));
  look.cover_outside =
      static_cast<float>(snow.number("cover_outside", look.cover_outside, 0.0, 1.0));
  scene.input.surface.object_layers.push_back({products::kSnowCoverage, "snow", m, true});
  return [look](SceneFile& s) { load_snow(s, look); };
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
