// The vocabulary of the products that flow between stages and the renderer
// (docs/architecture.md): every product is a file of plain data that one
// stage writes and others read, never a call into another stage.
//
//   height change   a GeoTIFF of metres added to (or replacing) the ground:
//                   snow depth (snow fall), dunes and marks (the new ground)
//   material mask   a GeoTIFF in [0, 1] placing a material: snow cover (snow
//                   cover, snow fall), the renderer's [[terrain.layer]] masks
//   normal detail   a tileable height tile bump-mapped on the ground: ripples
//   attributed mesh a PLY of a terrain::Mesh with named per-vertex
//                   attributes: snowy objects (snow fall), soil surfaces
//
// The names below are the contract of the attributed meshes: the stage that
// writes an attribute and every reader use these constants, never the bare
// strings.
#pragma once

namespace drift::terrain::products {

// Which object of the input list a vertex belongs to (0, 1, ...): a mesh of
// several objects splits back into them by it (terrain::split_by_attribute).
inline constexpr const char* kObjectIndex = "object";
// Snow on a vertex (snow fall, paper 003): depth in metres along the up
// direction, the probability of receiving snow, the coverage in [0, 1] the
// renderer blends the snow material by, and the adhesion speckle on steep
// faces.
inline constexpr const char* kSnowDepth = "snow_depth";
inline constexpr const char* kSnowProbability = "snow_probability";
inline constexpr const char* kSnowCoverage = "snow_coverage";
inline constexpr const char* kSnowAdhesion = "snow_adhesion";

}  // namespace drift::terrain::products
