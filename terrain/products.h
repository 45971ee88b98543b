// The vocabulary of the products that flow between stages and the renderer
// (docs/architecture.md): every product is a file of plain data that one
// stage writes and others read, never a call into another stage. Each has one
// declared form here or in the renderer's input (render/render_settings.h,
// render/surface.h), which reads it by form, not by the stage that made it:
//
//   height change   a GeoTIFF of metres laid on the ground: snow depth (snow
//                   fall). In memory a HeightChange; the renderer raises the
//                   surface it traces by every one (SceneInput::height_changes)
//   material mask   a GeoTIFF in [0, 1] placing a material: snow cover (snow
//                   cover, snow fall) for the snow, the renderer's
//                   [[terrain.layer]] masks for any other material
//   normal detail   a tileable height tile bump-mapped on the ground: ripples
//                   (dunes); the renderer's TerrainSurface::normal_details
//   attributed mesh a PLY of a terrain::Mesh with named per-vertex
//                   attributes (an AttributedMeshForm below): snowy objects
//                   (snow fall), soil surfaces (soil)
//
// The names below are the contract of the attributed meshes: the stage that
// writes an attribute and every reader use these constants, never the bare
// strings.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "terrain/grid.h"
#include "terrain/mesh.h"

namespace drift::terrain::products {

// Which object of the input list a vertex belongs to (0, 1, ...): a mesh of
// several objects splits back into them by it (split_objects).
inline constexpr const char* kObjectIndex = "object";
// Snow on a vertex (snow fall, paper 003): depth in metres along the up
// direction, the probability of receiving snow, the coverage in [0, 1] the
// renderer blends the snow material by, and the adhesion speckle on steep
// faces.
inline constexpr const char* kSnowDepth = "snow_depth";
inline constexpr const char* kSnowProbability = "snow_probability";
inline constexpr const char* kSnowCoverage = "snow_coverage";
inline constexpr const char* kSnowAdhesion = "snow_adhesion";
// The soil's moisture on its surface (soil), for wet-looking shading.
inline constexpr const char* kWetness = "wetness";

// A height change: metres laid on the ground (snow depth). Values below zero
// and nodata count as none; a stage that takes ground away writes new ground
// instead (a `ground` product, as dunes and marks do).
struct HeightChange {
  std::string name;  // what lies there ("snow depth"), for messages
  HeightField metres;
};

// The declared form of an attributed mesh file: the per-vertex attributes it
// carries, in the order its writer writes them, and who writes it (for the
// fix in a reader's message).
struct AttributedMeshForm {
  const char* name;        // "snowy objects"
  const char* written_by;  // "drift snow fall --mesh-out"
  std::vector<const char*> attributes;
};

// The snowy objects (drift snow fall --mesh-out, read by [snow] objects): all
// objects of the input list in one mesh, raised by their snow, relative to an
// origin, split back into objects by kObjectIndex.
inline const AttributedMeshForm kSnowyObjects{
    "snowy objects",
    "drift snow fall --mesh-out",
    {kSnowDepth, kSnowProbability, kSnowCoverage, kSnowAdhesion, kObjectIndex}};

// Throws drift::Error naming `file`, the missing attribute and the writer when
// `mesh` lacks one of `form`'s attributes or has one of another length.
void require_form(const Mesh& mesh, const AttributedMeshForm& form,
                  const std::filesystem::path& file);

// The objects of a mesh of several (a `form` with kObjectIndex, read from
// `file`), in their input order, each with its attributes and the mesh's
// origin; checks the form first.
std::vector<Mesh> split_objects(const Mesh& mesh, const AttributedMeshForm& form,
                                const std::filesystem::path& file);

}  // namespace drift::terrain::products
