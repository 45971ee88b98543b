#include "render/terrain_scene.h"

#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

#include "render/embree_ray.h"
#include "render/fast_math.h"
#include "render/ground_detail.h"
#include "render/paged_terrain.h"
#include "render/snow_flakes.h"
#include "render/streamed_heights.h"
#include "terrain/angles.h"
#include "terrain/bilinear.h"
#include "terrain/derivatives.h"
#include "terrain/error.h"
#include "terrain/local_frame.h"
#include "terrain/memory.h"
#include "terrain/products.h"
#include "terrain/raster_blocks.h"

namespace drift::render {

namespace {

// Embree calls this from C code: never throw through it; remember the message and
// raise it after the call returns (check_device).
thread_local std::string g_embree_message;
void embree_error(void*, RTCError, const char* message) {
  g_embree_message = message ? message : "unknown error";
}

void check_device(RTCDevice device, const char* what) {
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
    throw Error(std::string("Embree failed to ") + what + ": " + g_embree_message);
  }
}

// Embree grids are at most 32767 vertices a side (RTCGrid::width is 16-bit).
constexpr int kMaxGridSide = 32767;
// Embree's BVH over the height field's blocks in core (a user primitive a
// block of 16 x 16 cells: its build's references and BVH4 nodes), counted in
// the streamed scene's memory check.
constexpr std::uint64_t kBvhBytesABlock = 128;

// The ray's footprint (metres) where it hit.
double footprint(const RayCone& cone, const Hit& hit) { return cone.width_at(hit.distance); }

// The surface traced: the ground with every height change laid on it (none:
// nothing, the ground itself is traced).
std::optional<terrain::HeightField> raised_ground(const terrain::HeightField& ground,
                                                  const SceneInput& input) {
  std::optional<terrain::HeightField> raised;
  for (const terrain::products::HeightChange& change : input.height_changes)
    raised = add_height_change(raised ? *raised : ground, change.metres);
  return raised;
}

// What an object is made of: its preset (the scene's `material`) with its
// albedo, or plain diffuse albedo.
Material object_material(const terrain::PlacedMesh& placed) {
  Material m;
  if (!placed.material.empty()) {
    const std::optional<Material> preset = material_preset(placed.material);
    if (!preset) throw Error("unknown object material '" + placed.material + "'");
    m = *preset;
  }
  m.albedo = placed.albedo;
  return m;
}

}  // namespace

// The height field's user geometry (render/height_field.h). Every ray the
// scene traces carries its prepared form in an extended context (Embree
// passes the context to the callbacks unchanged), so that it is prepared once
// and not once per block.
struct HeightContext {
  RTCIntersectContext context;  // first: Embree sees only this
  const HeightRay* ray = nullptr;
};

void height_bounds(const RTCBoundsFunctionArguments* args) {
  const auto* blocks = static_cast<const HeightFieldBlocks*>(args->geometryUserPtr);
  Eigen::Vector3f lo, hi;
  blocks->block_bounds(args->primID, lo, hi);
  // A little wider than the block: Embree's own box tests only cull, and a
  // ray lying in a box's face (straight down along the DEM's west edge) must
  // reach the block's exact test.
  for (int a = 0; a < 3; ++a) {
    const float pad = 1e-6f * std::max(std::fabs(lo[a]), std::fabs(hi[a])) + 1e-6f;
    lo[a] -= pad, hi[a] += pad;
  }
  RTCBounds& b = *args->bounds_o;
  b.lower_x = lo.x(), b.lower_y = lo.y(), b.lower_z = lo.z();
  b.upper_x = hi.x(), b.upper_y = hi.y(), b.upper_z = hi.z();
}

// Ray i of a callback's N rays, prepared for the height field: the one the
// scene prepared (a single ray through its context) or made here in `own`.
const HeightRay& callback_ray(RTCRayN* rays, unsigned n, unsigned i, const HeightContext* ctx,
                              std::optional<HeightRay>& own) {
  if (n == 1 && ctx->ray) return *ctx->ray;
  own.emplace(Eigen::Vector3f(RTCRayN_org_x(rays, n, i), RTCRayN_org_y(rays, n, i),
                              RTCRayN_org_z(rays, n, i)),
              Eigen::Vector3f(RTCRayN_dir_x(rays, n, i), RTCRayN_dir_y(rays, n, i),
                              RTCRayN_dir_z(rays, n, i)));
  return *own;
}

// The terrain's geometry (height field or grids), committed as geometry 0.
void attach_as_terrain(RTCScene scene, RTCGeometry g) {
  rtcCommitGeometry(g);
  rtcAttachGeometryByID(scene, g, 0);
  rtcReleaseGeometry(g);
}

void height_intersect(const RTCIntersectFunctionNArguments* args) {
  const auto* blocks = static_cast<const HeightFieldBlocks*>(args->geometryUserPtr);
  const auto* ctx = reinterpret_cast<const HeightContext*>(args->context);
  RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hits = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (!args->valid[i]) continue;
    std::optional<HeightRay> own;
    const HeightRay& ray = callback_ray(rays, args->N, i, ctx, own);
    float tfar = RTCRayN_tfar(rays, args->N, i);
    HeightHit hit;
    if (!blocks->intersect(args->primID, ray, RTCRayN_tnear(rays, args->N, i), tfar, hit)) continue;
    RTCRayN_tfar(rays, args->N, i) = tfar;
    RTCHitN_Ng_x(hits, args->N, i) = hit.ng.x();
    RTCHitN_Ng_y(hits, args->N, i) = hit.ng.y();
    RTCHitN_Ng_z(hits, args->N, i) = hit.ng.z();
    RTCHitN_u(hits, args->N, i) = 0.0f;
    RTCHitN_v(hits, args->N, i) = 0.0f;
    RTCHitN_primID(hits, args->N, i) = args->primID;
    RTCHitN_geomID(hits, args->N, i) = args->geomID;
    RTCHitN_instID(hits, args->N, i, 0) = args->context->instID[0];
  }
}

void height_occluded(const RTCOccludedFunctionNArguments* args) {
  const auto* blocks = static_cast<const HeightFieldBlocks*>(args->geometryUserPtr);
  const auto* ctx = reinterpret_cast<const HeightContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (!args->valid[i]) continue;
    RTCRayN* rays = args->ray;
    std::optional<HeightRay> own;
    const HeightRay& ray = callback_ray(rays, args->N, i, ctx, own);
    if (blocks->occluded(args->primID, ray, RTCRayN_tnear(rays, args->N, i),
                         RTCRayN_tfar(rays, args->N, i)))
      RTCRayN_tfar(rays, args->N, i) = -std::numeric_limits<float>::infinity();
  }
}

struct TerrainScene::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<RTCGrid> grids;
  std::vector<RTCGrid> surround_grids;
  // A device (TBB's threads) and an empty scene built for tracing speed.
  void open() {
    device = rtcNewDevice("threads=0");
    if (!device) throw Error("cannot create an Embree device");
    rtcSetDeviceErrorFunction(device, embree_error, nullptr);
    scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  }
  // Builds the scene of what was attached; its lowest and highest z.
  std::pair<float, float> commit() {
    rtcCommitScene(scene);
    check_device(device, "build the scene");
    RTCBounds bounds;
    rtcGetSceneBounds(scene, &bounds);
    return {bounds.lower_z, bounds.upper_z};
  }
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

TerrainScene::TerrainScene(const SceneInput& input, TerrainGeometry geometry)
    : embree_(std::make_unique<Embree>()) {
  build(input, nullptr, geometry);
}

TerrainScene::TerrainScene(const SceneInput& input, terrain::HeightField&& terrain,
                           TerrainGeometry geometry)
    : embree_(std::make_unique<Embree>()) {
  build(input, &terrain, geometry);
}

TerrainScene::TerrainScene(const SceneInput& input, PagedTerrain& paged)
    : embree_(std::make_unique<Embree>()) {
  build_paged(input, paged);
}

TerrainScene::TerrainScene(const SceneInput& input, const std::filesystem::path& dem)
    : embree_(std::make_unique<Embree>()) {
  build_streamed(input, dem);
}

void TerrainScene::build_paged(const SceneInput& input, PagedTerrain& paged) {
  if (!input.height_changes.empty())
    throw Error(
        "an out-of-core terrain (--memory-budget) cannot have height changes (snow depth) "
        "laid on it; render without --memory-budget or lay them on the DEM first");
  paged_ = &paged;
  heights_ = paged.frame();
  width_ = heights_.width;
  height_ = heights_.height;
  dx_ = heights_.dx;
  dy_ = heights_.dy;
  exaggeration_ = paged.exaggeration();
  origin_ = paged.origin();
  highest_ = paged.highest();
  lowest_ = paged.lowest();
  extent_ = {(width_ - 1) * dx_, (height_ - 1) * dy_};
  surface_ = input.surface;
  surface_.cell = std::min(std::abs(static_cast<float>(paged.geo().cell_size_x())),
                           std::abs(static_cast<float>(paged.geo().cell_size_y())));
  coverage_ = coverage_channels(surface_);
  embree_->open();
  blocks_ = std::make_unique<HeightFieldBlocks>(heights_, paged, paged.take_block_bounds(),
                                                paged.take_coarse(), PagedTerrain::kGroup);
  attach_blocks();
  // The surround ring reads the DEM's whole edge from memory: not built here.
  for (const terrain::PlacedMesh& placed : input.meshes) attach_mesh(placed);
  std::tie(bottom_, top_) = embree_->commit();
}

void TerrainScene::build_streamed(const SceneInput& input, const std::filesystem::path& dem) {
  if (!input.height_changes.empty())
    throw Error("height changes (snow depth) need the terrain raster '" + dem.string() +
                "' whole in memory; lay them on the DEM first or render with float heights");
  exaggeration_ = static_cast<float>(input.vertical_exaggeration);
  // The codes and the strips in flight; the tree (0.67 B a cell) and
  // Embree's BVH over the blocks follow once the strips are gone.
  {
    terrain::RasterBlockReader probe(dem);
    const std::uint64_t cells = static_cast<std::uint64_t>(probe.width()) * probe.height();
    require_memory(streamed_heights_bytes(probe.width(), probe.height(),
                                          tbb::this_task_arena::max_concurrency()) +
                       cells * 3 / 4 + cells / 256 * kBvhBytesABlock,
                   "the terrain raster '" + dem.string() + "' as 16-bit heights",
                   "give --memory-budget to render it out of core, or resample the DEM");
  }
  StreamedHeights read = read_streamed_heights(dem, exaggeration_);
  heights_ = read.frame;
  width_ = heights_.width;
  height_ = heights_.height;
  dx_ = heights_.dx;
  dy_ = heights_.dy;
  origin_ = read.origin;
  highest_ = read.highest;
  lowest_ = read.lowest;
  extent_ = {(width_ - 1) * dx_, (height_ - 1) * dy_};
  surface_ = input.surface;
  surface_.cell = std::min(std::abs(read.geo.cell_size_x()), std::abs(read.geo.cell_size_y()));
  coverage_ = coverage_channels(surface_);
  embree_->open();
  // As attach_quantised_height_field: the ring from the decoded heights,
  // then the tree over them.
  SurroundGrids ring =
      build_surround(DemVertices{&heights_, width_, height_, dx_, dy_, origin_, exaggeration_,
                                 &read.heights, read.sum, read.sum_squares},
                     input.surround);
  blocks_ = std::make_unique<HeightFieldBlocks>(heights_, std::move(read.heights));
  attach_blocks();
  attach_ring(std::move(ring));
  for (const terrain::PlacedMesh& placed : input.meshes) attach_mesh(placed);
  std::tie(bottom_, top_) = embree_->commit();
}

void TerrainScene::build(const SceneInput& input, terrain::HeightField* adopt,
                         TerrainGeometry geometry) {
  const terrain::HeightField& ground = adopt ? *adopt : input.terrain;
  std::optional<terrain::HeightField> raised = raised_ground(ground, input);
  if (raised && adopt) *adopt = terrain::HeightField();  // the raised copy is traced instead
  const terrain::HeightField& dem = raised ? *raised : ground;
  check_terrain(dem);
  surface_ = input.surface;
  surface_.cell = std::min(std::abs(dem.geo().cell_size_x()), std::abs(dem.geo().cell_size_y()));
  coverage_ = coverage_channels(surface_);
  // Counted before fill_heights, which empties an adopted `dem` (counted
  // after, every adopted DEM was "small" and took the grid: issue 36).
  const std::size_t cells = dem.size();
  // A raised copy is the scene's own: its storage can become the heights.
  fill_heights(dem, raised ? &*raised : adopt, static_cast<float>(input.vertical_exaggeration));

  embree_->open();
  if (geometry == TerrainGeometry::Auto)
    geometry = cells < kHeightFieldMinCells ? TerrainGeometry::Grid : TerrainGeometry::HeightField;
  if (geometry == TerrainGeometry::HeightField16) {
    attach_quantised_height_field(input.surround);
  } else if (geometry == TerrainGeometry::Grid) {
    // The float3 vertex a cell and Embree's BVH over the grids.
    require_memory(cells * 32, "the terrain's grid geometry", "crop or resample the DEM");
    attach_terrain_grids();
    attach_surround(input.surround);
  } else {
    attach_height_field();
    attach_surround(input.surround);
  }
  for (const terrain::PlacedMesh& placed : input.meshes) attach_mesh(placed);
  std::tie(bottom_, top_) = embree_->commit();
}

void TerrainScene::check_terrain(const terrain::HeightField& dem) {
  if (dem.width() < 2 || dem.height() < 2) {
    throw Error("the terrain raster must be at least 2 x 2 cells, got " +
                std::to_string(dem.width()) + " x " + std::to_string(dem.height()));
  }
  if (!dem.geo().north_up()) {
    throw Error("the terrain raster is rotated; warp it north-up first (drift import)");
  }
  width_ = dem.width();
  height_ = dem.height();
  dx_ = static_cast<float>(dem.geo().cell_size_x());
  dy_ = static_cast<float>(dem.geo().cell_size_y());
  if (!(dx_ > 0) || !(dy_ > 0)) {
    throw Error("the terrain raster's cell size must be positive (north-up, metres)");
  }
  // Heights (shared with the caller's raster when adopted) and the min-max
  // tree, ~0.7 B a cell, and Embree's BVH over its blocks (the grid
  // geometry, kept for comparisons, needs 12 B of vertex and ~20 B of BVH).
  require_memory(dem.size() * 5, "the terrain scene", "crop or resample the DEM");
}

void TerrainScene::fill_heights(const terrain::HeightField& dem, terrain::HeightField* adopt,
                                float k) {
  // Local frame: origin at the DEM's centre (cell centres) and lowest height, so
  // float coordinates stay small. Nodata cells become the lowest valid height.
  const terrain::LocalFrame frame = terrain::local_frame(dem, "the terrain raster", k);
  const float lo = frame.lowest;
  exaggeration_ = k;
  origin_ = frame.origin;
  heights_.width = width_;
  heights_.height = height_;
  heights_.x0 = static_cast<float>(frame.x0);
  heights_.y0 = static_cast<float>(frame.y0);
  heights_.dx = dx_;
  heights_.dy = dy_;

  // The heights are the only copy of the terrain the scene keeps: shading
  // normals are computed from them at each hit (vertex_normal). An adopted
  // raster is rewritten in place (each cell read once, then overwritten).
  const std::size_t n = dem.size();
  const float* source = dem.values().data();
  if (adopt) {
    heights_.z = std::move(adopt->values());
    *adopt = terrain::HeightField();
  } else {
    heights_.z.resize(n);
  }
  if (adopt) source = heights_.z.data();
  float* z = heights_.z.data();
  const float z0 = static_cast<float>(origin_.z());
  tbb::parallel_for(0, height_, [&](int row) {
    for (int x = 0; x < width_; ++x) {
      const std::size_t i = static_cast<std::size_t>(row) * width_ + x;
      const float h = std::isnan(source[i]) ? lo : source[i];
      z[i] = h * k - z0;
    }
  });
  std::size_t hi_i = 0, lo_i = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (z[i] > z[hi_i]) hi_i = i;
    if (z[i] < z[lo_i]) lo_i = i;
  }
  const auto vertex = [&](std::size_t i) {
    return heights_.vertex(static_cast<int>(i % width_), static_cast<int>(i / width_));
  };
  highest_ = vertex(hi_i);
  lowest_ = vertex(lo_i);
  extent_ = {(width_ - 1) * dx_, (height_ - 1) * dy_};
}

void TerrainScene::attach_height_field() {
  blocks_ = std::make_unique<HeightFieldBlocks>(heights_);
  attach_blocks();
}

void TerrainScene::attach_quantised_height_field(const SurroundOptions& surround) {
  // 2 B a cell beside the 4 B of floats (the peak), then the floats are
  // decoded in place so the ring beyond the edge meets the heights the rays
  // meet, the ring is built, and the floats freed before the tree is built.
  QuantisedHeights quantised(heights_);
  tbb::parallel_for(0, height_, [&](int row) {
    for (int x = 0; x < width_; ++x)
      heights_.z[static_cast<std::size_t>(row) * width_ + x] = quantised.at(x, row);
  });
  SurroundGrids ring = build_surround(
      DemVertices{&heights_, width_, height_, dx_, dy_, origin_, exaggeration_}, surround);
  std::vector<float>().swap(heights_.z);
  blocks_ = std::make_unique<HeightFieldBlocks>(heights_, std::move(quantised));
  attach_blocks();
  attach_ring(std::move(ring));
}

void TerrainScene::attach_blocks() {
  RTCGeometry g = rtcNewGeometry(embree_->device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(g, blocks_->block_count());
  rtcSetGeometryUserData(g, blocks_.get());
  rtcSetGeometryBoundsFunction(g, height_bounds, nullptr);
  rtcSetGeometryIntersectFunction(g, height_intersect);
  rtcSetGeometryOccludedFunction(g, height_occluded);
  attach_as_terrain(embree_->scene, g);
  terrain_geometries_ = 1;
  mesh_material_.push_back(surface_.ground);
  mesh_covers_.emplace_back();
}

std::size_t TerrainScene::terrain_bytes() const {
  return heights_.z.size() * sizeof(float) + (blocks_ ? blocks_->bytes() : 0) +
         vertices_.size() * sizeof(Eigen::Vector3f);
}

void TerrainScene::attach_terrain_grids() {
  // Embree's float3 vertex buffer from the heights.
  vertices_.resize(heights_.z.size());
  tbb::parallel_for(0, height_, [&](int row) {
    for (int x = 0; x < width_; ++x)
      vertices_[static_cast<std::size_t>(row) * width_ + x] = heights_.vertex(x, row);
  });
  // Grids of at most kMaxGridSide vertices a side over one shared vertex
  // buffer (stride = raster width); neighbours share their edge row.
  for (int gy = 0; gy < height_ - 1; gy += kMaxGridSide - 1) {
    for (int gx = 0; gx < width_ - 1; gx += kMaxGridSide - 1) {
      RTCGrid g;
      g.startVertexID = static_cast<unsigned>(static_cast<std::size_t>(gy) * width_ + gx);
      g.stride = static_cast<unsigned>(width_);
      g.width = static_cast<unsigned short>(std::min(kMaxGridSide, width_ - gx));
      g.height = static_cast<unsigned short>(std::min(kMaxGridSide, height_ - gy));
      embree_->grids.push_back(g);
    }
  }
  RTCGeometry grid_geometry = rtcNewGeometry(embree_->device, RTC_GEOMETRY_TYPE_GRID);
  rtcSetSharedGeometryBuffer(grid_geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                             vertices_.data(), 0, sizeof(Eigen::Vector3f), vertices_.size());
  rtcSetSharedGeometryBuffer(grid_geometry, RTC_BUFFER_TYPE_GRID, 0, RTC_FORMAT_GRID,
                             embree_->grids.data(), 0, sizeof(RTCGrid), embree_->grids.size());
  attach_as_terrain(embree_->scene, grid_geometry);
  terrain_geometries_ = 1;
  mesh_material_.push_back(surface_.ground);
  mesh_covers_.emplace_back();
}

void TerrainScene::attach_surround(const SurroundOptions& options) {
  DemVertices dem{&heights_, width_, height_, dx_, dy_, origin_, exaggeration_};
  attach_ring(build_surround(dem, options));
}

void TerrainScene::attach_ring(SurroundGrids ring) {
  if (ring.grids.empty()) return;
  surround_vertices_ = std::move(ring.vertices);
  surround_normals_ = std::move(ring.normals);
  std::vector<RTCGrid>& grids = embree_->surround_grids;
  for (const SurroundGrids::Grid& g : ring.grids)
    grids.push_back({g.start, g.stride, g.width, g.height});
  RTCGeometry geometry = rtcNewGeometry(embree_->device, RTC_GEOMETRY_TYPE_GRID);
  rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                             surround_vertices_.data(), 0, sizeof(Eigen::Vector3f),
                             surround_vertices_.size());
  rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_GRID, 0, RTC_FORMAT_GRID, grids.data(), 0,
                             sizeof(RTCGrid), grids.size());
  rtcCommitGeometry(geometry);
  surround_geometry_ = rtcAttachGeometry(embree_->scene, geometry);
  rtcReleaseGeometry(geometry);
  surround_reach_ = ring.reach;
  // Keep the per-geometry tables indexed by id.
  mesh_material_.resize(surround_geometry_ + 1, surface_.ground);
  mesh_covers_.resize(surround_geometry_ + 1);
}

void TerrainScene::attach_mesh(const terrain::PlacedMesh& placed) {
  // Triangle geometry with its own (copied, shifted) buffers.
  RTCGeometry geom = rtcNewGeometry(embree_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                        RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                        placed.mesh.positions.size()));
  const Eigen::Vector3d shift = placed.position - origin_;  // CRS -> local
  for (std::size_t i = 0; i < placed.mesh.positions.size(); ++i) {
    const Eigen::Vector3d local = placed.mesh.positions[i].cast<double>() + shift;
    for (int c = 0; c < 3; ++c) v[3 * i + c] = static_cast<float>(local[c]);
  }
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                                             RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                             placed.mesh.triangles.size()));
  for (std::size_t t = 0; t < placed.mesh.triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) idx[3 * t + c] = static_cast<unsigned>(placed.mesh.triangles[t][c]);
  }
  rtcCommitGeometry(geom);
  const unsigned id = rtcAttachGeometry(embree_->scene, geom);
  rtcReleaseGeometry(geom);
  if (mesh_material_.size() <= id) {
    mesh_material_.resize(id + 1);
    mesh_covers_.resize(id + 1);
  }
  mesh_material_[id] = object_material(placed);
  // An attributed mesh (terrain/products.h) may carry the attributes the
  // object layers place their materials by (snow coverage).
  MeshCover& covers = mesh_covers_[id];
  covers.values.resize(surface_.object_layers.size());
  for (std::size_t i = 0; i < surface_.object_layers.size(); ++i) {
    const std::string& name = surface_.object_layers[i].attribute;
    if (const std::vector<float>* values = placed.mesh.attribute(name)) {
      if (values->size() != placed.mesh.positions.size())
        throw Error("a mesh's '" + name + "' attribute must have one value per vertex");
      covers.values[i] = *values;
      covers.triangles = placed.mesh.triangles;
    }
  }
}

TerrainScene::~TerrainScene() = default;

float TerrainScene::z_at(int c, int r) const {
  // The level of detail's heights where it is on (the geometry's, so the
  // shading reads no page the rays did not need), else the DEM's.
  if (paged_ || (blocks_ && (blocks_->lod_on() || blocks_->quantised())))
    return blocks_->height(c, r);
  return heights_.at(c, r);
}

float TerrainScene::height_at(float x, float y) const {
  auto h = [&](int xx, int rr) { return z_at(xx, rr); };
  return terrain::bilinear_clamped(h, width_, height_, (x - heights_.x0) / dx_,
                                   (heights_.y0 - y) / dy_);
}

Eigen::Vector3f TerrainScene::vertex_normal(int x, int row) const {
  // Horn's gradient of the exaggerated heights, as the slope and aspect
  // rasters compute it (terrain/derivatives.h), edges included.
  const auto z = [&](int xx, int rr) { return z_at(xx, rr); };
  const terrain::Gradient g = terrain::horn_gradient(z, width_, height_, dx_, dy_, x, row);
  return Eigen::Vector3f(-g.dzdx, -g.dzdy, 1.0f).normalized();
}

Eigen::Vector3f TerrainScene::smooth_normal(float px, float py) const {
  // Bilinear vertex normals at the hit's cell position. Inside the DEM (a
  // ring of cells from its edge) the four corners' Horn gradients share one
  // 4x4 stencil of heights, read once from the rows in place of 36 reads
  // through z_at: the same operations in the same order as vertex_normal's,
  // so the same bits (the heights hold no NaN: fill_heights).
  const terrain::BilinearCell<float> c =
      terrain::clamped_cell((px - heights_.x0) / dx_, (heights_.y0 - py) / dy_, width_, height_);
  if (paged_ || (blocks_ && blocks_->lod_on()) || c.x0 < 1 || c.y0 < 1 || c.x1 + 1 >= width_ ||
      c.y1 + 1 >= height_) {
    auto vn = [&](int xx, int rr) { return vertex_normal(xx, rr); };
    return terrain::bilinear_blend(vn(c.x0, c.y0), vn(c.x1, c.y0), vn(c.x0, c.y1), vn(c.x1, c.y1),
                                   c.tx, c.ty)
        .normalized();
  }
  float z[4][4];                          // z[r][k]: row y0 - 1 + r, column x0 - 1 + k
  if (blocks_ && blocks_->quantised()) {  // 16-bit: no float rows to read
    for (int r = 0; r < 4; ++r)
      for (int k = 0; k < 4; ++k) z[r][k] = blocks_->height(c.x0 - 1 + k, c.y0 - 1 + r);
  } else {
    for (int r = 0; r < 4; ++r) {
      const float* row =
          heights_.z.data() + static_cast<std::size_t>(c.y0 - 1 + r) * width_ + c.x0 - 1;
      for (int k = 0; k < 4; ++k) z[r][k] = row[k];
    }
  }
  // The normal of the vertex at stencil (k, r), 1 <= k, r <= 2.
  auto vn = [&](int k, int r) {
    const terrain::Gradient g =
        terrain::horn_3x3(z[r - 1][k - 1], z[r - 1][k], z[r - 1][k + 1], z[r][k - 1], z[r][k + 1],
                          z[r + 1][k - 1], z[r + 1][k], z[r + 1][k + 1], dx_, dy_);
    return Eigen::Vector3f(-g.dzdx, -g.dzdy, 1.0f).normalized();
  };
  return terrain::bilinear_blend(vn(1, 1), vn(2, 1), vn(1, 2), vn(2, 2), c.tx, c.ty).normalized();
}

Eigen::Vector3f TerrainScene::surround_normal(unsigned grid, float u, float v) const {
  // Embree's u, v run over the whole grid in [0, 1] (columns, rows).
  const RTCGrid& g = embree_->surround_grids[grid];
  const float fu = std::clamp(u, 0.0f, 1.0f) * static_cast<float>(g.width - 1);
  const float fv = std::clamp(v, 0.0f, 1.0f) * static_cast<float>(g.height - 1);
  const int i = std::min(static_cast<int>(fu), g.width - 2);
  const int j = std::min(static_cast<int>(fv), g.height - 2);
  auto n = [&](int a, int b) {
    return surround_normals_[g.startVertexID + static_cast<std::size_t>(j + b) * g.stride + i + a];
  };
  const float tu = fu - static_cast<float>(i), tv = fv - static_cast<float>(j);
  return terrain::bilinear_blend(n(0, 0), n(1, 0), n(0, 1), n(1, 1), tu, tv).normalized();
}

namespace {

// The nearest hit of a ray from o along d (geomID invalid: none). The ray is
// prepared for the height field only where there is one (the grid geometry
// has no use for it: 1.3 % of the default frame).
RTCRayHit nearest_hit(RTCScene scene, bool height_field, const Eigen::Vector3f& o,
                      const Eigen::Vector3f& d) {
  std::optional<HeightRay> ray;
  HeightContext context;
  rtcInitIntersectContext(&context.context);
  if (height_field) context.ray = &ray.emplace(o, d);
  RTCRayHit rh = nearest_ray_hit(o, d);
  rtcIntersect1(scene, &context.context, &rh);
  return rh;
}

}  // namespace

bool TerrainScene::hits(const Eigen::Vector3f& o, const Eigen::Vector3f& d) const {
  return nearest_hit(embree_->scene, blocks_ != nullptr, o, d).hit.geomID !=
         RTC_INVALID_GEOMETRY_ID;
}

float TerrainScene::hit_distance(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                 Eigen::Vector3f* normal) const {
  const RTCRayHit rh = nearest_hit(embree_->scene, blocks_ != nullptr, o, d);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::numeric_limits<float>::infinity();
  if (normal) {
    const Eigen::Vector3f n = Eigen::Vector3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z).normalized();
    *normal = n.z() < 0.0f ? Eigen::Vector3f(-n) : n;
  }
  return rh.ray.tfar;
}

bool TerrainScene::intersect(const Eigen::Vector3f& o, const Eigen::Vector3f& d, Hit& hit,
                             const RayCone& cone) const {
  if (recorder_) recorder_->traced(o, d, std::numeric_limits<float>::infinity(), false);
  return shade_hit(nearest_hit(embree_->scene, blocks_ != nullptr, o, d), o, d, hit, cone);
}

void TerrainScene::intersect_coherent(int n, const Eigen::Vector3f* o, const Eigen::Vector3f* d,
                                      const RayCone* cones, Hit* hits, bool* found) const {
  // The height field's user geometry prepares each ray once per call in the
  // single-ray path (HeightContext); in a packet it would prepare it once
  // per block, so it keeps single rays (as does a batch too large).
  if (blocks_ || n > kCoherentRays) {
    for (int i = 0; i < n; ++i) found[i] = intersect(o[i], d[i], hits[i], cones[i]);
    return;
  }
  alignas(32) RTCRayHit8 packet{};
  alignas(32) int valid[8] = {};
  for (int i = 0; i < n; ++i) {
    if (recorder_) recorder_->traced(o[i], d[i], std::numeric_limits<float>::infinity(), false);
    valid[i] = -1;
    packet.ray.org_x[i] = o[i].x(), packet.ray.org_y[i] = o[i].y(), packet.ray.org_z[i] = o[i].z();
    packet.ray.dir_x[i] = d[i].x(), packet.ray.dir_y[i] = d[i].y(), packet.ray.dir_z[i] = d[i].z();
    packet.ray.tnear[i] = 0.0f;
    packet.ray.tfar[i] = std::numeric_limits<float>::infinity();
    packet.ray.mask[i] = 0xffffffffu;
    packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
  }
  // One traversal for the packet: its rays leave one point in nearly one
  // direction (a pixel's camera rays), so they share most of the BVH's nodes.
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect8(valid, embree_->scene, &context, &packet);
  for (int i = 0; i < n; ++i) {
    RTCRayHit rh = nearest_ray_hit(o[i], d[i]);
    rh.ray.tfar = packet.ray.tfar[i];
    rh.hit.Ng_x = packet.hit.Ng_x[i], rh.hit.Ng_y = packet.hit.Ng_y[i];
    rh.hit.Ng_z = packet.hit.Ng_z[i];
    rh.hit.u = packet.hit.u[i], rh.hit.v = packet.hit.v[i];
    rh.hit.primID = packet.hit.primID[i], rh.hit.geomID = packet.hit.geomID[i];
    found[i] = shade_hit(rh, o[i], d[i], hits[i], cones[i]);
  }
}

void TerrainScene::occluded_coherent(int n, const Eigen::Vector3f* o, const Eigen::Vector3f* d,
                                     float max_distance, bool* blocked) const {
  if (blocks_ || n > kCoherentRays) {
    for (int i = 0; i < n; ++i) blocked[i] = occluded(o[i], d[i], max_distance);
    return;
  }
  alignas(32) RTCRay8 packet{};
  alignas(32) int valid[8] = {};
  for (int i = 0; i < n; ++i) {
    if (recorder_) recorder_->traced(o[i], d[i], max_distance, true);
    valid[i] = -1;
    packet.org_x[i] = o[i].x(), packet.org_y[i] = o[i].y(), packet.org_z[i] = o[i].z();
    packet.dir_x[i] = d[i].x(), packet.dir_y[i] = d[i].y(), packet.dir_z[i] = d[i].z();
    packet.tnear[i] = 0.0f;
    packet.tfar[i] = max_distance;
    packet.mask[i] = 0xffffffffu;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcOccluded8(valid, embree_->scene, &context, &packet);
  for (int i = 0; i < n; ++i) blocked[i] = packet.tfar[i] < 0.0f;  // -inf on a hit
}

bool TerrainScene::shade_hit(const RTCRayHit& rh, const Eigen::Vector3f& o,
                             const Eigen::Vector3f& d, Hit& hit, const RayCone& cone) const {
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.distance = rh.ray.tfar;
  hit.position = o + d * rh.ray.tfar;
  hit.direction = d;
  const bool surround = rh.hit.geomID == surround_geometry_;
  std::optional<Eigen::Vector3f> facet;  // beyond the DEM: its smooth normal, facing up
  if (surround) facet = surround_normal(rh.hit.primID, rh.hit.u, rh.hit.v);
  const Eigen::Vector3f n =
      rh.hit.geomID < terrain_geometries_ || surround
          ? shade_terrain_hit(hit, cone, facet)
          : shade_mesh_hit(rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v,
                           {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z}, hit, footprint(cone, hit));
  // Face the ray: a mesh may be seen from either side, and terrain from below
  // at the edges. (Embree's Ng of our grids points down: rows run south.)
  hit.normal = n.dot(d) > 0 ? Eigen::Vector3f(-n) : n;
  return true;
}

Eigen::Vector3f TerrainScene::shade_terrain_hit(Hit& hit, const RayCone& cone,
                                                const std::optional<Eigen::Vector3f>& facet) const {
  // Smooth shading: bilinear vertex normals at the hit's cell position (on
  // the DEM), or the facet's normal turned up (beyond it).
  const Eigen::Vector3f n = facet ? (facet->z() < 0.0f ? Eigen::Vector3f(-*facet) : *facet)
                                  : smooth_normal(hit.position.x(), hit.position.y());
  const Eigen::Vector3d world = origin_ + hit.position.cast<double>();
  // Material rules see the real relief: heights and slopes without the
  // vertical exaggeration (n ~ (-k Zx, -k Zy, 1)).
  Relief relief;
  relief.altitude = static_cast<float>(world.z() / exaggeration_);
  relief.slope_deg = fast_atan2(n.head<2>().norm(), std::abs(n.z()) * exaggeration_) *
                     terrain::kDegreesPerRadian<float>;
  relief.z = world.z();
  relief.ray = hit.direction;
  const SurfacePoint surface =
      shade_terrain(surface_, world.x(), world.y(), n, footprint(cone, hit), relief, &coverage_);
  hit.material = surface.material;
  hit.coverage = surface.coverage;
  return surface.normal;
}

Eigen::Vector3f TerrainScene::shade_mesh_hit(unsigned geometry, unsigned triangle, float u, float v,
                                             const Eigen::Vector3f& ng, Hit& hit,
                                             double footprint) const {
  hit.material = mesh_material_[geometry];
  hit.coverage = {};  // the objects themselves have no channel
  Eigen::Vector3f n = ng.normalized();
  const GroundDetail& detail = hit.material.detail;
  if (detail.variation > 0.0f || detail.bump > 0.0f) {
    // A preset's relief and mottle (render/ground_detail.h) in world space,
    // read on the face turned up (the detail is laid out for ground); the
    // normal turned back after, as intersect() faces it to the ray anyway.
    const Eigen::Vector3d world = origin_ + hit.position.cast<double>();
    const float side = n.z() < 0.0f ? -1.0f : 1.0f;
    const DetailedGround g = ground_detail(hit.material, world.x(), world.y(), world.z(), side * n,
                                           footprint, surface_.cell);
    hit.material.albedo = g.albedo;
    hit.material.roughness = g.roughness;
    n = side * g.normal;
  }
  if (geometry >= mesh_covers_.size()) return n;
  const MeshCover& covers = mesh_covers_[geometry];
  for (std::size_t i = 0; i < covers.values.size(); ++i) {
    if (covers.values[i].empty()) continue;
    // The attribute interpolated over the triangle (Embree's barycentrics).
    const std::vector<float>& values = covers.values[i];
    const std::array<int, 3>& tri = covers.triangles[triangle];
    const float mean = std::clamp(
        (1.0f - u - v) * values[tri[0]] + u * values[tri[1]] + v * values[tri[2]], 0.0f, 1.0f);
    // Below full coverage, flakes (render/snow_flakes.h) where the layer asks.
    const ObjectLayer& layer = surface_.object_layers[i];
    const float c = layer.flakes ? flake_cover(origin_ + hit.position.cast<double>(), n, mean,
                                               footprint, hit.direction)
                                 : mean;
    hit.material = mix(hit.material, layer.material, c);
    cover(hit.coverage, coverage_.object_layers[i], c);
  }
  return n;
}

bool TerrainScene::occluded(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                            float max_distance) const {
  if (recorder_) recorder_->traced(o, d, max_distance, true);
  std::optional<HeightRay> prepared;
  HeightContext context;
  rtcInitIntersectContext(&context.context);
  if (blocks_) context.ray = &prepared.emplace(o, d);
  RTCRay ray{};
  ray.org_x = o.x(), ray.org_y = o.y(), ray.org_z = o.z();
  ray.dir_x = d.x(), ray.dir_y = d.y(), ray.dir_z = d.z();
  ray.tnear = 0.0f;
  ray.tfar = max_distance;
  ray.mask = 0xffffffffu;
  rtcOccluded1(embree_->scene, &context.context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

}  // namespace drift::render
