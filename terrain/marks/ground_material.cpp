#include "terrain/marks/ground_material.h"

#include <cmath>
#include <cstdio>

#include "terrain/angles.h"
#include "terrain/error.h"

namespace drift::marks {

void Material::validate(const std::string& what) const {
  for (const terrain::Parameter<Material>& p : material_parameters()) {
    if (!p.admits(p.get(*this)))
      throw terrain::ParameterError(
          what + ": material '" + name + "' " + p.key,
          "is " + terrain::refused_value(p.get(*this)) + "; it must lie in " + p.range());
  }
}

terrain::SlopeRule Material::slope_rule() const {
  terrain::SlopeRule r;
  // 90 degrees: the material stands vertical and never slips (paper: snow).
  r.tan_repose =
      theta_deg >= 90.0 ? std::numeric_limits<double>::infinity() : terrain::tan_degrees(theta_deg);
  r.fraction = sigma;
  r.rough = true;  // paper 000, 3.5: sigma sets the slumped slope's roughness
  return r;
}

std::optional<Material> material_preset(const std::string& name) {
  // Paper 000, section 4: figs. 7 (sand), 8 (mud), 9 (snow); sigma 0.2 (3.5).
  // Mud's heave of one footing width: soft mud fails undrained in Prandtl's
  // mechanism, lifting ground about a footing width beyond each edge
  // (Terzaghi 1943; docs/marks.md, "Mud's heave").
  if (name == "sand") return Material{"sand", 30.0, 1.0, 0.2, 0.0};
  if (name == "mud") return Material{"mud", 60.0, 0.8, 0.2, 1.0};
  if (name == "snow") return Material{"snow", 90.0, 0.0, 0.2, 0.0};
  return std::nullopt;
}

std::string material_preset_names() { return "sand, mud, snow"; }

std::uint8_t MaterialField::add(const Material& m) {
  for (std::size_t i = 0; i < table.size(); ++i) {
    const Material& t = table[i];
    if (t.name == m.name && t.theta_deg == m.theta_deg && t.alpha == m.alpha &&
        t.sigma == m.sigma && t.heave == m.heave)
      return static_cast<std::uint8_t>(i);
  }
  if (table.size() >= 255) throw Error("more than 255 different ground materials");
  table.push_back(m);
  return static_cast<std::uint8_t>(table.size() - 1);
}

MaterialField materials_from_raster(const terrain::Grid<float>& indices,
                                    const std::vector<Material>& table, const std::string& what,
                                    int col0, int row0) {
  if (table.empty() || table.size() > 255)
    throw Error(what + ": a material raster needs 1 to 255 materials");
  MaterialField f;
  f.table = table;
  f.index = terrain::Grid<std::uint8_t>(indices.width(), indices.height(), 0);
  for (std::size_t i = 0; i < indices.size(); ++i) {
    const float v = indices.values()[i];
    if (!(v >= 0.0f && v < static_cast<float>(table.size()) && v == std::floor(v))) {
      const int col = col0 + static_cast<int>(i % static_cast<std::size_t>(indices.width()));
      const int row = row0 + static_cast<int>(i / static_cast<std::size_t>(indices.width()));
      char value[32];  // %g: 1e+30 and inf as such, not 31 digits
      std::snprintf(value, sizeof value, "%g", static_cast<double>(v));
      throw Error(what + ": cell (" + std::to_string(col) + ", " + std::to_string(row) +
                  ") holds " + value + "; each cell must hold a whole number from 0 to " +
                  std::to_string(table.size() - 1) + " (" + material_preset_names() +
                  ", in that order)");
    }
    f.index.values()[i] = static_cast<std::uint8_t>(v);
  }
  return f;
}

MaterialField materials_from_snow_depth(const terrain::Grid<float>& snow_depth, double min_depth,
                                        const Material& ground, const Material& snow) {
  MaterialField f;
  f.table = {ground, snow};
  f.index = terrain::Grid<std::uint8_t>(snow_depth.width(), snow_depth.height(), 0);
  for (std::size_t i = 0; i < snow_depth.size(); ++i) {
    const float d = snow_depth.values()[i];
    f.index.values()[i] = (std::isfinite(d) && d > min_depth) ? 1 : 0;
  }
  return f;
}

}  // namespace drift::marks
