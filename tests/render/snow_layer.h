// Snow on a test surface as a scene's [snow] puts it there
// (pipeline/scene_snow.cpp): its cover a material mask of the snow material,
// laid last, in flakes where thin, translucent by its depth, burying normal
// details; and on objects by their snow-coverage attribute.
#pragma once

#include <optional>
#include <utility>

#include "render/surface.h"
#include "terrain/products.h"

namespace drift::testing {

inline render::MaterialLayer snow_layer(
    terrain::HeightField cover, std::optional<terrain::HeightField> depth = {},
    const render::Material& snow = *render::material_preset("snow")) {
  render::MaterialLayer layer;
  layer.name = "snow";
  layer.material = render::full_override(snow);
  layer.mask = std::move(cover);
  layer.flakes = true;
  if (depth) layer.thickness = render::LayerThickness{std::move(*depth), 400.0f};
  layer.buries_details = true;
  return layer;
}

inline render::ObjectLayer snow_on_objects() {
  return {terrain::products::kSnowCoverage, "snow", *render::material_preset("snow"), true};
}

}  // namespace drift::testing
