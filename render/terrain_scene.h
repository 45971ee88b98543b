// The Embree 3 scene of a render: the height field as a user geometry over its
// heights (render/height_field.h: 4 bytes a DEM cell plus a min-max tree, the
// same triangles as Embree's grid geometry) plus triangle meshes.
//
// Coordinates: the interface speaks the raster's own CRS (x east, y north,
// metres) and heights in metres. Inside, everything is shifted by `origin()`
// (the DEM's centre) so that UTM-sized numbers keep float precision in Embree.
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "render/height_field.h"
#include "render/render_settings.h"

struct RTCRayHit;  // Embree's (embree3/rtcore_ray.h)

namespace drift::render {

class PagedTerrain;

struct Hit {
  float distance = 0.0f;
  Eigen::Vector3f position{0, 0, 0};   // local (origin-shifted) coordinates
  Eigen::Vector3f direction{0, 0, 0};  // the ray's (unit): footprints stretch along it
  Eigen::Vector3f normal{0, 0, 1};     // unit shading normal, facing the ray
  Material material{{0, 0, 0}};        // what the BSDF sees (render/bsdf.h)
  Coverage coverage{};                 // by TerrainScene::coverage_names()
};

// A ray's footprint as a cone (Akenine-Moller et al. 2019, "Texture level of
// detail strategies for real-time ray tracing"): `width` metres at the origin,
// growing by `spread` metres per metre travelled. It picks bump-map levels.
struct RayCone {
  float width = 0.0f;
  float spread = 0.0f;

  // The footprint's width (metres) `distance` along the ray.
  float width_at(float distance) const { return width + spread * distance; }
};

// Sees every ray a TerrainScene traces, from any thread: benchmarks record
// the path tracer's own rays with it and replay them raw
// (tests/bench/render_bench.cpp, BM_RawEmbreeSameRays).
class RayRecorder {
 public:
  virtual ~RayRecorder() = default;
  // `shadow`: an occlusion ray within max_distance; else a nearest-hit ray.
  virtual void traced(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float max_distance,
                      bool shadow) = 0;
};

// How the height field is given to Embree: its heights with a min-max tree
// (render/height_field.h, about 5 B a cell), or Embree's grid geometry over a
// float3 vertex a cell (about 36 B a cell at the peak, and 1.45 times faster
// on the default scene: 6.4 s against 9.3 s for 320x180 at 32 spp on one
// thread). Both trace the same triangles. Auto, the default, takes the grid
// below kHeightFieldMinCells cells (4096^2; the grid's peak there is about
// 600 MB) and the height field from there on, where memory is what limits.
// HeightField16: the height field over 16-bit heights (render/height_field.h,
// QuantisedHeights; `drift render --height-bits 16`), about 3 B a cell held.
enum class TerrainGeometry { Auto, HeightField, Grid, HeightField16 };
inline constexpr std::size_t kHeightFieldMinCells = std::size_t{4096} * 4096;

class TerrainScene {
 public:
  // Throws drift::Error for an empty or all-nodata terrain. NaN (nodata) cells
  // are filled with the lowest valid height so that holes read as low ground.
  explicit TerrainScene(const SceneInput& input, TerrainGeometry geometry = TerrainGeometry::Auto);
  // The same with the terrain taken from `terrain` (input.terrain is not
  // read): its storage becomes the scene's heights, so a DEM's cells are held
  // once; `terrain` is left empty.
  TerrainScene(const SceneInput& input, terrain::HeightField&& terrain,
               TerrainGeometry geometry = TerrainGeometry::Auto);
  // The terrain read on demand from `paged` (render/paged_terrain.h), which
  // must outlive the scene; input.terrain is not read. Throws drift::Error
  // for what needs the whole DEM in memory (height changes laid on it, the
  // surround ring).
  TerrainScene(const SceneInput& input, PagedTerrain& paged);
  // The terrain read from the raster `dem` (band 1) strip by strip and held
  // as 16-bit heights (TerrainGeometry::HeightField16), each strip quantised
  // as it is read, so the DEM's floats never all exist (issue 36: the peak
  // of `drift render --height-bits 16`); input.terrain is not read. The same
  // heights, tree, ring and images bit for bit as the scene of the whole DEM
  // read as floats with HeightField16. Throws drift::Error naming the file
  // as PagedTerrain does, and for height changes (they need the DEM whole).
  TerrainScene(const SceneInput& input, const std::filesystem::path& dem);
  ~TerrainScene();
  TerrainScene(const TerrainScene&) = delete;
  TerrainScene& operator=(const TerrainScene&) = delete;

  // The nearest hit, with the surface's layers (snow, ripples) evaluated for a
  // footprint given by `cone`.
  bool intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, Hit& hit,
                 const RayCone& cone = {}) const;
  // The nearest hits of n <= kCoherentRays rays that leave about one point
  // in about one direction (a pixel's camera rays), as intersect() gives
  // each (found[i]: ray i met something), traced as one Embree packet on the
  // grid geometry; the height field traces them one by one.
  static constexpr int kCoherentRays = 8;
  void intersect_coherent(int n, const Eigen::Vector3f* origins, const Eigen::Vector3f* dirs,
                          const RayCone* cones, Hit* hits, bool* found) const;
  // occluded() of n <= kCoherentRays rays of about one direction from
  // nearby points (the sun's shadow rays of a pixel's samples) into
  // blocked[i], as one Embree packet on the grid geometry.
  void occluded_coherent(int n, const Eigen::Vector3f* origins, const Eigen::Vector3f* dirs,
                         float max_distance, bool* blocked) const;
  // True if anything lies on the ray within (0, max_distance).
  bool occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir,
                float max_distance) const;
  // Raw Embree: whether the ray meets anything (rtcIntersect1 alone, nothing
  // shaded, not recorded). The ceiling intersect() is measured against.
  bool hits(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir) const;
  // Raw Embree's nearest hit: its distance (infinity: none) and geometric
  // normal (unit, facing up on the terrain); for tests of the geometry.
  float hit_distance(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir,
                     Eigen::Vector3f* normal = nullptr) const;
  // Bytes the terrain geometry holds: heights, min-max tree or float3
  // vertices (Embree's own BVH not included).
  std::size_t terrain_bytes() const;
  // The frame's level of detail (render/height_field.h, LodView; issue 36):
  // on the height field only (Embree's grid geometry is always full
  // resolution); set before tracing, never while rays are traced.
  void set_lod(const LodView& view) {
    if (blocks_) blocks_->set_lod(view);
  }
  // Every ray intersect() and occluded() trace goes to `recorder` too (none:
  // nullptr); for benchmarks, not to be changed while rays are traced.
  void record_rays(RayRecorder* recorder) { recorder_ = recorder; }

  // CRS -> local coordinates and back.
  Eigen::Vector3d origin() const { return origin_; }
  Eigen::Vector3f to_local(const Eigen::Vector3d& world) const {
    return (world - origin_).cast<float>();
  }

  // Terrain facts in local coordinates, for default cameras.
  Eigen::Vector3f highest_point() const { return highest_; }
  Eigen::Vector3f lowest_point() const { return lowest_; }
  Eigen::Vector2f extent() const { return extent_; }  // metres east-west, north-south
  float height_at(float x, float y) const;            // bilinear, local coordinates
  // The shading normal on the DEM at local (x, y): Horn's vertex normals
  // blended bilinearly (clamped to the DEM), unit length.
  Eigen::Vector3f smooth_normal(float x, float y) const;
  // Lowest and highest z of all geometry (terrain and meshes), local.
  float bottom() const { return bottom_; }
  // The names of Hit::coverage's channels (render/coverage.h).
  const std::vector<std::string>& coverage_names() const { return coverage_.names; }
  float top() const { return top_; }
  // Metres the ground reaches beyond the DEM's edge (render/surround.h).
  float surround_reach() const { return surround_reach_; }

 private:
  // The constructor's steps: checks the raster's shape and takes its size;
  // fills the heights in the local frame (from `adopt`'s own storage when
  // given); adds the terrain geometry over them; adds one object.
  void build(const SceneInput& input, terrain::HeightField* adopt, TerrainGeometry geometry);
  void check_terrain(const terrain::HeightField& dem);
  void fill_heights(const terrain::HeightField& dem, terrain::HeightField* adopt,
                    float vertical_exaggeration);
  void attach_terrain_grids();
  void attach_height_field();
  void attach_blocks();
  void build_paged(const SceneInput& input, PagedTerrain& paged);
  void build_streamed(const SceneInput& input, const std::filesystem::path& dem);
  // Vertex (c, r)'s height, local frame: from heights_ or the pages.
  float z_at(int c, int r) const;
  void attach_mesh(const terrain::PlacedMesh& placed);

  // The hit's material and coverage on the terrain (a footprint from
  // `cone`) or on mesh `geometry`'s `triangle` at barycentrics (u, v) with
  // geometric normal `ng` (seen by a footprint `footprint` metres wide);
  // each returns the shading normal, not yet facing the ray.
  // intersect()'s answer from Embree's record `rh` of the ray (o, d).
  bool shade_hit(const RTCRayHit& rh, const Eigen::Vector3f& o, const Eigen::Vector3f& d, Hit& hit,
                 const RayCone& cone) const;
  Eigen::Vector3f shade_terrain_hit(Hit& hit, const RayCone& cone,
                                    const std::optional<Eigen::Vector3f>& facet = {}) const;
  Eigen::Vector3f shade_mesh_hit(unsigned geometry, unsigned triangle, float u, float v,
                                 const Eigen::Vector3f& ng, Hit& hit, double footprint) const;

  // The unit shading normal at vertex (x, row), from the vertex buffer.
  Eigen::Vector3f vertex_normal(int x, int row) const;

  struct Embree;
  std::unique_ptr<Embree> embree_;
  RayRecorder* recorder_ = nullptr;
  int width_ = 0, height_ = 0;
  float dx_ = 1.0f, dy_ = 1.0f;
  float exaggeration_ = 1.0f;
  Eigen::Vector3d origin_{0, 0, 0};
  // The filled, exaggerated heights in the local frame, row 0 = north, and
  // the min-max tree over them (TerrainGeometry::HeightField) or Embree's
  // float3 vertex buffer (TerrainGeometry::Grid).
  HeightGrid heights_;
  std::unique_ptr<HeightFieldBlocks> blocks_;
  const PagedTerrain* paged_ = nullptr;  // out of core: heights_.z is empty
  std::vector<Eigen::Vector3f> vertices_;
  TerrainSurface surface_;
  CoverageChannels coverage_;
  // What an object's per-vertex attributes place on it (surface_.object_layers):
  // each layer's values (empty: the mesh lacks the attribute) and the
  // triangles to interpolate them over.
  struct MeshCover {
    std::vector<std::vector<float>> values;  // by object layer
    std::vector<std::array<int, 3>> triangles;
  };
  std::vector<Material> mesh_material_;  // by Embree geometry id
  std::vector<MeshCover> mesh_covers_;   // likewise
  unsigned terrain_geometries_ = 0;      // geometry ids [0, n) are terrain grids
  // The ground beyond the DEM's edge (render/surround.h): its vertex buffer,
  // grids and Embree geometry id (none: -1).
  void attach_surround(const SurroundOptions& options);
  void attach_ring(SurroundGrids ring);
  // The height field over 16-bit heights; the float heights are freed
  // (the ring beyond the edge is built from the decoded ones first).
  void attach_quantised_height_field(const SurroundOptions& surround);
  std::vector<Eigen::Vector3f> surround_vertices_;
  std::vector<Eigen::Vector3f> surround_normals_;  // smooth shading (render/surround.h)
  // The smooth normal at (u, v) of surround grid `grid` (Embree's grid-local
  // hit coordinates).
  Eigen::Vector3f surround_normal(unsigned grid, float u, float v) const;
  unsigned surround_geometry_ = ~0u;
  float surround_reach_ = 0.0f;
  Eigen::Vector3f highest_{0, 0, 0}, lowest_{0, 0, 0};
  float bottom_ = 0.0f, top_ = 0.0f;
  Eigen::Vector2f extent_{0, 0};
};

}  // namespace drift::render
