// Ground materials for marks (paper 000, 3.4-3.5 and section 4): how steep the
// ground stands after slipping (theta), how much of the material an object
// pushes aside is displaced rather than compressed (alpha), and how rough the
// slipped slopes are (sigma). The paper's presets:
//
//   name   theta (deg)  alpha  sigma  heave  look (paper figs. 7-9)
//   sand   30           1.0    0.2    0      crumbled rims
//   mud    60           0.8    0.2    1      sharp walls, a packed floor, a wide low heave
//   snow   90           0.0    0.2    0      clean compressed prints, no rim
//
// theta in (0, 90] (90: never slips), alpha in [0, 1], sigma in (0, 0.5],
// heave in [0, 4] (issue 32, not the paper: the width of the heave beside a
// print in footing widths; 0: the paper's rim on the contact's ring).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "terrain/grid.h"
#include "terrain/parameter.h"
#include "terrain/slope_relax.h"

namespace drift::marks {

struct Material {
  std::string name = "sand";
  double theta_deg = 30.0;  // angle of the slope after slipping (deg)
  double alpha = 1.0;       // displaced share of the material an object pushes out
  double sigma = 0.2;       // roughness: share of a slope's excess moved per pass
  // Width of the heave the displaced volume spreads over beside a press, in
  // footing widths (displacement.cpp, docs/marks.md "Mud's heave"; 0: the
  // paper's ring).
  double heave = 0.0;

  // Throws terrain::ParameterError naming `what`, the material, the key and
  // the bad value (the ranges: material_parameters()).
  void validate(const std::string& what) const;
  terrain::SlopeRule slope_rule() const;
};

// The ranges of a material's numbers, one row each, as a track file names
// them (key "theta", "alpha", "roughness"): the one check of Material::validate
// and of track files' material tables (data: material_parameters.toml beside
// this header, compiled by scripts/parameter_table.cmake).
const std::vector<terrain::Parameter<Material>>& material_parameters();

// The paper's preset by name (sand, mud, snow), or nothing.
std::optional<Material> material_preset(const std::string& name);
std::string material_preset_names();  // "sand, mud, snow"

// Materials per cell: a table and, per cell, an index into it (all cells index 0
// while `index` is empty).
struct MaterialField {
  std::vector<Material> table{Material{}};
  terrain::Grid<std::uint8_t> index;

  // The table's index of `m` (added if it is not there yet; at most 255).
  std::uint8_t add(const Material& m);
  const Material& at(int cell) const {
    return table[index.empty() ? 0 : index.values()[static_cast<std::size_t>(cell)]];
  }
};

// Per-region materials from a raster a user paints or derives (issue 32: the
// material belongs to the ground): each cell holds the index of its material
// in `table` (0, 1, ...; whole numbers). Throws drift::Error naming `what`,
// the cell and the value for anything else (NaN, a fraction, out of range).
// `col0`, `row0`: where the grid lies in the raster `what` names (a window of
// it, marks_blocks.h), for the message.
MaterialField materials_from_raster(const terrain::Grid<float>& indices,
                                    const std::vector<Material>& table, const std::string& what,
                                    int col0 = 0, int row0 = 0);

// Per-region materials from a snow-depth raster (drift snow fall): `snow` where
// the snow is deeper than `min_depth` (m), `ground` elsewhere. The raster must
// match the ground's size.
MaterialField materials_from_snow_depth(const terrain::Grid<float>& snow_depth, double min_depth,
                                        const Material& ground, const Material& snow);

}  // namespace drift::marks
