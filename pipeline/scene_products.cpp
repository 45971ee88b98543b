#include "pipeline/scene_products.h"

#include "pipeline/object_list.h"
#include "terrain/raster_io.h"

namespace drift::pipeline {

const std::vector<StageSection>& stage_sections() {
  // A new stage's section is one more row (and its file scene_<stage>.cpp).
  static const std::vector<StageSection> sections = {snow_section(), ripples_section()};
  return sections;
}

std::string product_key(const StageSection& section, const ProductFileKey& file) {
  return std::string(section.name) + "." + file.key;
}

terrain::HeightField read_metric_raster(const std::filesystem::path& file) {
  terrain::HeightField grid = terrain::read_raster(file);
  require_metric_crs(grid, file);
  return grid;
}

}  // namespace drift::pipeline
