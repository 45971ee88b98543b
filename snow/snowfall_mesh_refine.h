// Subdivision of object meshes before snowfall: the polygon variant raises
// vertices by their snow, so coarse polygons give coarse snow (paper 003, 3.2:
// "the polygons must be subdivided").
#pragma once

#include "terrain/mesh.h"

namespace drift::snow {

// Splits edges longer than max_edge (metres) at their midpoints until none is
// longer, keeping the mesh conforming (an edge is split for both its triangles)
// and the winding. Drops normals and attributes. max_edge <= 0 returns the mesh
// unchanged. Deterministic.
terrain::Mesh refine_mesh(const terrain::Mesh& mesh, double max_edge);

}  // namespace drift::snow
