// Surfaces of the voxel soil (paper 004, sec. 3.3): the iso-0.5 surface of
// rho extracted with OpenVDB's volumeToMesh (one .cpp, surface_vdb.cpp, includes
// openvdb/openvdb.h), and
// the density written as an OpenVDB grid for Blender and Houdini.
//
// Vertical ridges (thesis 3.3, fig. 42-43; fix suggested in 5.3.2, fig. 59):
// Marching Cubes interpolates between voxel centres, and a column's density
// (the fraction of its top voxel filled) is not a linear function of its
// height, so a slope between two columns comes out stepped. Before
// extraction, StraightSlopes replaces the density around the top T of every
// pile by the ramp d(z) = clamp(0.5 + (T - z) / (2 R), 0, 1) (z at voxel
// centres, R = ramp_voxels): linear in z with d = 0.5 exactly at T, and
// linear between neighbouring columns at the same z, so the 0.5 crossings lie
// on the straight line joining the column tops for slopes up to R voxels per
// voxel. Only piles that hold soil (kMinSurfaceSoil) are reshaped (within
// their own voxels and the air up to the next span); falling soil keeps its
// density, and bare ground and bare bodies stay without soil, so a scenario
// without soil has no soil surface.
#pragma once

#include <filesystem>
#include <vector>

#include "terrain/mesh.h"
#include "terrain/soil/height_spans.h"
#include "terrain/soil/soil_state.h"

namespace drift::soil {

enum class RidgeFix { Off, StraightSlopes };

// Soil (voxels, sum of rho) a pile must hold for the ridge fix to reshape it:
// a trace left by soil running thin is below half a voxel in every voxel and
// so has no surface without the fix; with it, it would become a sheet lying
// on the ground (z-fighting flecks on bodies and terrain).
inline constexpr float kMinSurfaceSoil = 0.05f;
inline bool holds_soil(const HeightSpan& pile) { return pile.soil >= kMinSurfaceSoil; }

struct SurfaceOptions {
  RidgeFix ridges = RidgeFix::StraightSlopes;
  int ramp_voxels = 3;      // R, [1, 16]
  double adaptivity = 0.0;  // volumeToMesh's: 0 keeps every triangle, 1 merges flat areas most
};

// The density the surface is extracted from (rho, reshaped per `options`).
std::vector<float> surface_density(const SoilState& state, const SurfaceOptions& options);

// The iso-0.5 surface of `field` (a grid of `state.shape`) in metres,
// outward-facing, closed where the field meets the grid's sides. Empty if the
// field is empty.
// `kind`: Band (the default) activates only the voxels beside the iso-value,
// Full every non-zero voxel (as before issue 33's item 8, kept to test that
// both give the same mesh).
enum class IsoGrid { Band, Full };
terrain::Mesh iso_surface(const terrain::Grid3Shape& shape, const std::vector<float>& field,
                          IsoGrid kind = IsoGrid::Band);

// The soil's surface, with a per-vertex "wetness" (for the renderer's wet
// coat): the moisture field at the vertex (moisture_at).
terrain::Mesh soil_surface(const SoilState& state, const SurfaceOptions& options);

// The moisture of the soil at p (metres): the field's trilinear mean over the
// voxels around p weighted by the soil they hold (a surface vertex lies
// between full and empty voxels); 0 where no soil is near.
float moisture_at(const SoilState& state, const Eigen::Vector3f& p);

// Writes grids "density" (rho), "collision" (psi) and "wetness" (the
// moisture field where there is soil) as fog volumes and "velocity" (m/s, a vector grid),
// voxel size and origin in metres, atomically; the same state gives the same
// bytes. Throws drift::Error naming the file.
void write_density_vdb(const SoilState& state, const std::filesystem::path& path);

}  // namespace drift::soil
