// The stages' sections of a scene file ([snow], [ripples]): the one place
// where a stage's keys and `drift render` flags map onto the renderer's
// products (terrain/products.h: height changes, material masks, normal-detail
// tiles, attributed meshes). Each stage has one small file,
// pipeline/scene_<stage>.cpp, and a row in stage_sections(); scene_file.cpp
// and cmd_render.cpp read this table and know no stage.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/scene.h"
#include "pipeline/toml_section.h"

namespace drift::pipeline {

// A key of a stage's section naming a product file, and the `drift render`
// flag that overrides it.
struct ProductFileKey {
  const char* key;   // "cover": [snow] cover, SceneFile::product_file("snow.cover")
  const char* flag;  // "--snow-cover"
  const char* what;  // "snow cover raster", for the flag's help
};

struct StageSection {
  const char* name;  // the scene file's section, [name]
  std::vector<ProductFileKey> files;
  // Reads the section's other keys (the files are read before, into
  // scene.product_files; `section.present()` is false when the scene has no
  // such section) and returns what puts its products into scene.input once the
  // terrain is loaded, or nothing when the section makes no products: then
  // its flags are an error.
  SceneFile::Loader (*read)(Section& section, SceneFile& scene);
};

// Every stage's section, in the order the scene file is read in (and the
// order of their flags in `drift render --help`).
const std::vector<StageSection>& stage_sections();

// The stages' sections (pipeline/scene_<stage>.cpp).
StageSection snow_section();
StageSection ripples_section();

// "snow.cover": the product file's key in SceneFile::product_files.
std::string product_key(const StageSection& section, const ProductFileKey& file);

// Reads a raster the scene places in metres; degrees are an error with the fix.
terrain::HeightField read_metric_raster(const std::filesystem::path& file);

}  // namespace drift::pipeline
