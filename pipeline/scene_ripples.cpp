// [ripples]: the ripple tile of drift dunes --model ripples in a scene, a
// normal-detail tile bump-mapped on the ground (paper 002, section 5).
#include "pipeline/scene_products.h"
#include "render/surface.h"
#include "terrain/error.h"

namespace drift::pipeline {

namespace {

// The tile as a slope pyramid at `texel` metres a cell (0: its own cell
// size), into normal detail `index`.
void load_ripples(SceneFile& scene, std::size_t index, double texel_metres) {
  const std::filesystem::path file = scene.product_file("ripples.raster");
  terrain::HeightField tile = read_metric_raster(file);
  const double native = tile.geo().cell_size_x();
  const double texel = texel_metres > 0.0 ? texel_metres : native;
  // A ripple field scaled to another cell size is scaled as a whole, heights
  // too, so its slopes (what shading sees) stay those simulated.
  if (native > 0.0 && texel != native) {
    for (float& v : tile.values()) v = static_cast<float>(v * (texel / native));
  }
  try {
    scene.input.surface.normal_details[index].slopes = render::SlopePyramid(tile, texel);
  } catch (const Error& e) {
    throw Error("ripple raster '" + file.string() + "': " + e.what());
  }
}

SceneFile::Loader read_ripples(Section& rip, SceneFile& scene) {
  if (!rip.present()) return {};
  if (scene.product_file("ripples.raster").empty())
    rip.invalid_table("needs 'raster' (a tileable height field from drift dunes --model ripples)");
  render::NormalDetail layer;
  // At least 0.1 mm: the bump map divides by it (1e-39 overflowed inside Embree).
  const double cell = rip.number("cell", 0.0, 1e-4, 100.0);
  layer.rotation_deg = rip.number("rotation", 0.0, -360.0, 360.0);
  layer.strength = static_cast<float>(rip.number("strength", 1.0, 0.0, 100.0));
  if (const auto fade = rip.vector<2>("fade_slope", 0.0, 90.0)) {
    if (!((*fade)[0] < (*fade)[1]))
      rip.invalid("fade_slope", "must be [start, end] with start < end");
    layer.fade_start_deg = static_cast<float>((*fade)[0]);
    layer.fade_end_deg = static_cast<float>((*fade)[1]);
  }
  std::vector<render::NormalDetail>& details = scene.input.surface.normal_details;
  const std::size_t index = details.size();
  details.push_back(std::move(layer));
  return [index, cell](SceneFile& s) { load_ripples(s, index, cell); };
}

}  // namespace

StageSection ripples_section() {
  return {"ripples", {{"raster", "--ripples", "ripple height tile"}}, read_ripples};
}

}  // namespace drift::pipeline
