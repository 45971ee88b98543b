// Stabilisation of snow on a triangle mesh (paper 003, 2.3(3)): the three cases
// of stabilise_grid.h, with the neighbours given by the mesh's edges, so snow
// moves within an object, under overhangs too (paper 3.2).
//
// Each vertex holds snow over its horizontal footprint a_i (a third of the
// horizontal projection of its upward-facing triangles); its snow surface is
// z_i + depth_i. A vertex with no footprint (on walls, undersides) holds no snow.
// Between two holding vertices at horizontal distance L the excess is
// e = (H_i - H_j) - tan(repose) L, and the volume that levels the pair to repose is
// e / (1/a_i + 1/a_j).
//
// Shedding (what the paper leaves out: "moving snow between objects needs the
// polygons in the direction of fall"): a holding vertex on the edge of the
// holding region (next to a vertex that holds nothing, or on an open border of
// the mesh) can keep snow up to tan(repose) x r_i above itself, r_i = sqrt(a_i)/2
// the radius of its footprint; more falls off, straight down. The caller drops
// the shed volume on the ground below the vertex. Not modelled: shed snow
// landing on another object or on a lower part of the same object.
#pragma once

#include <vector>

#include "snow/stabilise_grid.h"
#include "terrain/mesh.h"

namespace drift::snow {

// Horizontal footprint per vertex (m^2), see above.
std::vector<double> vertex_footprints(const terrain::Mesh& mesh);

struct MeshStabiliseReport {
  int iterations = 0;
  bool converged = false;
  std::vector<double> shed;  // per vertex: volume (m^3) that fell off there
};

// volume: snow per vertex (m^3), updated in place; footprint from vertex_footprints.
// Mass: sum(volume) + sum(shed) is conserved to double rounding. Sequential
// (Gauss-Seidel in vertex order): deterministic.
MeshStabiliseReport stabilise_mesh(const terrain::Mesh& mesh, const std::vector<double>& footprint,
                                   std::vector<double>& volume,
                                   const StabiliseOptions& options = {});

}  // namespace drift::snow
