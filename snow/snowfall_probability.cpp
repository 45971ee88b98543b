#include "snow/snowfall_probability.h"

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "snow/occlusion_horizon.h"
#include "terrain/error.h"
#include "terrain/offscreen/depth_map.h"
#include "terrain/offscreen/osmesa_depth_renderer.h"

namespace drift::snow {

namespace {

using Eigen::Vector3d;
using terrain::depth_bias;
using terrain::DepthMap;
using terrain::GroundGeometry;
using terrain::LightFrame;
using terrain::OsmesaDepthRenderer;

struct Box {
  Vector3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
};

Box mesh_box(const terrain::Mesh& m) {
  Box b;
  for (const auto& p : m.positions) {
    b.lo = b.lo.cwiseMin(p.cast<double>());
    b.hi = b.hi.cwiseMax(p.cast<double>());
  }
  return b;
}

// Light-space bounds of a world box: a, b across, c towards the source.
struct Rect {
  double a_lo = 1e300, a_hi = -1e300, b_lo = 1e300, b_hi = -1e300, c_lo = 1e300, c_hi = -1e300;
  bool overlaps(const Rect& o) const {
    return a_lo <= o.a_hi && o.a_lo <= a_hi && b_lo <= o.b_hi && o.b_lo <= b_hi;
  }
};

Rect project_box(const LightFrame& f, const Box& box) {
  Rect r;
  for (int corner = 0; corner < 8; ++corner) {
    const Vector3d p((corner & 1) ? box.hi.x() : box.lo.x(), (corner & 2) ? box.hi.y() : box.lo.y(),
                     (corner & 4) ? box.hi.z() : box.lo.z());
    const Vector3d q = f.project(p);
    r.a_lo = std::min(r.a_lo, q.x()), r.a_hi = std::max(r.a_hi, q.x());
    r.b_lo = std::min(r.b_lo, q.y()), r.b_hi = std::max(r.b_hi, q.y());
    r.c_lo = std::min(r.c_lo, q.z()), r.c_hi = std::max(r.c_hi, q.z());
  }
  return r;
}

// Sets the map's corner, texel and size to cover `r` with a 2-texel margin; the
// texel grows if the map would exceed 16384 a side.
void frame_map(DepthMap& map, const Rect& r, double texel) {
  const double extent = std::max(r.a_hi - r.a_lo, r.b_hi - r.b_lo);
  texel = std::max(texel, extent / 16000.0);
  map.texel = texel;
  map.a0 = r.a_lo - 2 * texel;
  map.b0 = r.b_lo - 2 * texel;
  map.width = static_cast<int>(std::ceil((r.a_hi - r.a_lo) / texel)) + 4;
  map.height = static_cast<int>(std::ceil((r.b_hi - r.b_lo) / texel)) + 4;
}

// What the ground hides from one direction.
class TerrainOccluder {
 public:
  TerrainOccluder(const SnowScene& scene, const Vector3d& w, TerrainOcclusion mode,
                  OsmesaDepthRenderer* renderer, HorizonSweeper& sweeper)
      : scene_(scene), w_(w) {
    if (mode == TerrainOcclusion::Sweep) {
      shadow_ = sweeper.shadow(w);
      return;
    }
    map_.emplace();
    map_->frame = LightFrame::toward(w);
    Box box;
    box.lo = Vector3d(scene.x0, scene.y0 - (scene.ground.height() - 1) * scene.dy, scene.ground_lo);
    box.hi = Vector3d(scene.x0 + (scene.ground.width() - 1) * scene.dx, scene.y0, scene.ground_hi);
    const Rect r = project_box(map_->frame, box);
    frame_map(*map_, r, std::min(scene.dx, scene.dy));
    GroundGeometry g{&scene.ground, scene.x0, scene.y0, scene.dx, scene.dy};
    renderer->render(*map_, r.c_lo, r.c_hi, {}, &g);
  }

  // cos_phi: the cell's normal . w.
  bool cell_lit(int col, int row, double cos_phi) const {
    if (cos_phi <= 0.0) return false;
    if (map_) {
      // The texel nearest a cell centre may hold a neighbouring facet: bias for the
      // steepest facet around the cell, or a lit concave kink shows acne.
      const int W = scene_.ground.width(), H = scene_.ground.height();
      for (auto [i, j] : {std::pair{col - 1, row}, {col + 1, row}, {col, row - 1}, {col, row + 1}})
        if (i >= 0 && j >= 0 && i < W && j < H)
          cos_phi = std::min(cos_phi, scene_.ground_normal(i, j).dot(w_));
      return map_->lit_biased(scene_.cell_point(col, row), depth_bias(map_->texel, cos_phi));
    }
    return shadow_.at(col, row) <= scene_.ground(col, row);
  }

  bool point_lit(const Vector3d& p, const Vector3d& n) const {
    if (map_) return map_->lit(p, n);
    const double col = scene_.col_of(p.x()), row = scene_.row_of(p.y());
    if (col < 0 || row < 0 || col > scene_.ground.width() - 1 || row > scene_.ground.height() - 1)
      return true;
    // S >= h everywhere, equal where lit: compare with the interpolated S, allowing for
    // float rounding only.
    const double tolerance = 1e-5 * (1.0 + std::abs(p.z()));
    return p.z() >= shadow_.bilinear_at(col, row) - tolerance;
  }

 private:
  const SnowScene& scene_;
  Vector3d w_;
  ShadowSurface shadow_;
  std::optional<DepthMap> map_;
};

// Sample points inside a triangle (centroid and three points towards the corners),
// away from its edges where neighbouring faces meet.
std::array<Vector3d, 4> face_samples(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d g = (a + b + c) / 3.0;
  return {g, (a + 2 * g) / 3.0, (b + 2 * g) / 3.0, (c + 2 * g) / 3.0};
}

// Each object's bounding box and unit face normals (zero for a degenerate face).
struct ObjectGeometry {
  std::vector<Box> boxes;
  std::vector<std::vector<Vector3d>> face_normals;
};

ObjectGeometry object_geometry(const SnowScene& scene) {
  ObjectGeometry g;
  for (const terrain::Mesh& m : scene.meshes) {
    g.boxes.push_back(mesh_box(m));
    std::vector<Vector3d>& normals = g.face_normals.emplace_back(m.triangle_count());
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const auto& tri = m.triangles[t];
      const Vector3d a = m.positions[tri[0]].cast<double>(), b = m.positions[tri[1]].cast<double>(),
                     c = m.positions[tri[2]].cast<double>();
      const Vector3d n = (b - a).cross(c - a);
      normals[t] = n.norm() > 0 ? Vector3d(n.normalized()) : Vector3d::Zero();
    }
  }
  return g;
}

// What the objects hide from one direction: a depth map around each object,
// holding every object that overlaps it.
struct ObjectMaps {
  LightFrame frame;
  std::vector<DepthMap> maps;
  std::vector<Rect> rects;  // each object's light-space bounds
  double finest = 0.0;      // the finest texel of any map (or the ground cell)

  bool lit(const Vector3d& p, const Vector3d& n) const {
    const Vector3d q = frame.project(p);
    for (const DepthMap& m : maps)
      if (m.contains(q.x(), q.y()) && !m.lit(p, n)) return false;
    return true;
  }
};

ObjectMaps object_maps(const SnowScene& scene, const std::vector<Box>& boxes,
                       const LightFrame& frame, const ProbabilityOptions& options, double cell,
                       OsmesaDepthRenderer* renderer) {
  const std::size_t n = boxes.size();
  ObjectMaps out{frame, std::vector<DepthMap>(n), std::vector<Rect>(n), cell};
  for (std::size_t o = 0; o < n; ++o) out.rects[o] = project_box(frame, boxes[o]);
  for (std::size_t o = 0; o < n; ++o) {
    const Rect& r = out.rects[o];
    const double extent = std::max({r.a_hi - r.a_lo, r.b_hi - r.b_lo, 1e-3});
    const double texel =
        options.object_texel > 0 ? options.object_texel : std::min(0.5 * cell, extent / 1024.0);
    out.maps[o].frame = frame;
    frame_map(out.maps[o], r, texel);
    out.finest = std::min(out.finest, out.maps[o].texel);
    std::vector<const terrain::Mesh*> drawn;
    double c_lo = r.c_lo, c_hi = r.c_hi;
    for (std::size_t q = 0; q < n; ++q) {
      if (!out.rects[q].overlaps(r)) continue;
      drawn.push_back(&scene.meshes[q]);
      c_lo = std::min(c_lo, out.rects[q].c_lo), c_hi = std::max(c_hi, out.rects[q].c_hi);
    }
    renderer->render(out.maps[o], c_lo, c_hi, drawn, nullptr);
  }
  return out;
}

// Ground cells that objects may shade from direction w (sampled K x K): those
// under an object's shadow volume whose centres project into its map.
terrain::Grid<unsigned char> cells_near_objects(const SnowScene& scene,
                                                const std::vector<Box>& boxes, const Vector3d& w,
                                                const ObjectMaps& objects) {
  const int W = scene.ground.width(), H = scene.ground.height();
  terrain::Grid<unsigned char> near_object(W, H, 0);
  for (std::size_t o = 0; o < boxes.size(); ++o) {
    const Box& b = boxes[o];
    const double t_max = std::max(0.0, (b.hi.z() - scene.ground_lo) / w.z());
    const double x_lo = std::min(b.lo.x(), b.lo.x() - t_max * w.x());
    const double x_hi = std::max(b.hi.x(), b.hi.x() - t_max * w.x());
    const double y_lo = std::min(b.lo.y(), b.lo.y() - t_max * w.y());
    const double y_hi = std::max(b.hi.y(), b.hi.y() - t_max * w.y());
    const int c0 = std::max(0, static_cast<int>(std::floor(scene.col_of(x_lo))) - 1);
    const int c1 = std::min(W - 1, static_cast<int>(std::ceil(scene.col_of(x_hi))) + 1);
    const int r0 = std::max(0, static_cast<int>(std::floor(scene.row_of(y_hi))) - 1);
    const int r1 = std::min(H - 1, static_cast<int>(std::ceil(scene.row_of(y_lo))) + 1);
    const double margin = std::hypot(scene.dx, scene.dy) + 2 * objects.maps[o].texel;
    const Rect& r = objects.rects[o];
    for (int row = r0; row <= r1; ++row)
      for (int col = c0; col <= c1; ++col) {
        const Vector3d q = objects.frame.project(scene.cell_point(col, row));
        if (q.x() >= r.a_lo - margin && q.x() <= r.a_hi + margin && q.y() >= r.b_lo - margin &&
            q.y() <= r.b_hi + margin)
          near_object(col, row) = 1;
      }
  }
  return near_object;
}

// The lit share of a cell near objects, from K x K points over it (the centre
// by the terrain's own test), and its n . w in `cos_phi`.
float cell_lit_share(const SnowScene& scene, const TerrainOccluder& occluder,
                     const ObjectMaps& objects, const Vector3d& w, int K, int col, int row,
                     double& cos_phi) {
  const int W = scene.ground.width(), H = scene.ground.height();
  const Vector3d n = scene.ground_normal(col, row);
  cos_phi = n.dot(w);
  int count = 0;
  for (int j = 0; j < K; ++j)
    for (int i = 0; i < K; ++i) {
      const double c = std::clamp(col + (i + 0.5) / K - 0.5, 0.0, W - 1.0);
      const double r = std::clamp(row + (j + 0.5) / K - 0.5, 0.0, H - 1.0);
      const Vector3d p(scene.x0 + c * scene.dx, scene.y0 - r * scene.dy,
                       terrain::bilinear_clamped(scene.ground, c, r));
      const bool seen = (i * 2 + 1 == K && j * 2 + 1 == K)
                            ? occluder.cell_lit(col, row, cos_phi)
                            : cos_phi > 0 && occluder.point_lit(p, n);
      count += seen && objects.lit(p, n);
    }
  return static_cast<float>(count) / static_cast<float>(K * K);
}

// Adds one direction's weighted lit share (and lit share x n . w) of every
// ground cell to `acc` (and `acc_facing`).
void accumulate_ground(const SnowScene& scene, const TerrainOccluder& occluder,
                       const ObjectMaps& objects, const terrain::Grid<unsigned char>& near_object,
                       const Vector3d& w, float weight, int K, terrain::Grid<float>& acc,
                       terrain::Grid<float>& acc_facing) {
  const int W = scene.ground.width(), H = scene.ground.height();
  auto one_cell = [&](int col, int row) {
    double cos_phi;
    float lit;
    if (!near_object(col, row)) {
      cos_phi = scene.ground_normal(col, row).dot(w);
      lit = occluder.cell_lit(col, row, cos_phi) ? 1.0f : 0.0f;
    } else {
      lit = cell_lit_share(scene, occluder, objects, w, K, col, row, cos_phi);
    }
    acc(col, row) += weight * lit;
    acc_facing(col, row) += weight * lit * static_cast<float>(std::max(0.0, cos_phi));
  };
  // Cells in 64 x 64 blocks: a transposed shadow surface reads well within a block.
  constexpr int B = 64;
  tbb::parallel_for(tbb::blocked_range2d<int>(0, (H + B - 1) / B, 0, (W + B - 1) / B),
                    [&](const tbb::blocked_range2d<int>& blocks) {
                      for (int by = blocks.rows().begin(); by < blocks.rows().end(); ++by)
                        for (int bx = blocks.cols().begin(); bx < blocks.cols().end(); ++bx)
                          for (int row = by * B; row < std::min(H, (by + 1) * B); ++row)
                            for (int col = bx * B; col < std::min(W, (bx + 1) * B); ++col)
                              one_cell(col, row);
                    });
}

// Adds one direction's weighted lit share of every object face (4 samples).
void accumulate_faces(const SnowScene& scene, const ObjectGeometry& geometry,
                      const TerrainOccluder& occluder, const ObjectMaps& objects, const Vector3d& w,
                      float weight, SnowProbability& out) {
  for (std::size_t o = 0; o < scene.meshes.size(); ++o) {
    const terrain::Mesh& m = scene.meshes[o];
    tbb::parallel_for(std::size_t{0}, m.triangle_count(), [&](std::size_t t) {
      const Vector3d& n = geometry.face_normals[o][t];
      const double facing = n.dot(w);
      if (facing <= 0.0) return;
      const auto& tri = m.triangles[t];
      int count = 0;
      for (const Vector3d& p :
           face_samples(m.positions[tri[0]].cast<double>(), m.positions[tri[1]].cast<double>(),
                        m.positions[tri[2]].cast<double>()))
        count += occluder.point_lit(p, n) && objects.lit(p, n);
      const float lit = static_cast<float>(count) / 4.0f;
      out.faces[o][t] += weight * lit;
      out.facing[o][t] += weight * lit * static_cast<float>(facing);
    });
  }
}

// Divides every sum by the same float sum of weights: a point lit in every
// map gets exactly 1.
void normalise(SnowProbability& out, float total_weight) {
  for (auto* g : {&out.ground, &out.ground_facing})
    for (float& v : g->values()) v /= total_weight;
  for (std::size_t o = 0; o < out.faces.size(); ++o) {
    for (float& v : out.faces[o]) v /= total_weight;
    for (float& v : out.facing[o]) v /= total_weight;
  }
}

}  // namespace

SnowProbability snow_probability(const SnowScene& scene, const std::vector<FallDirection>& dirs,
                                 const ProbabilityOptions& options, const ProgressFn& progress) {
  const int W = scene.ground.width(), H = scene.ground.height();
  SnowProbability out;
  out.ground = terrain::Grid<float>(W, H, 0.0f);
  out.ground_facing = terrain::Grid<float>(W, H, 0.0f);
  for (const terrain::Mesh& m : scene.meshes) {
    out.faces.emplace_back(m.triangle_count(), 0.0f);
    out.facing.emplace_back(m.triangle_count(), 0.0f);
  }
  const ObjectGeometry geometry = object_geometry(scene);
  std::unique_ptr<OsmesaDepthRenderer> renderer;
  if (!scene.meshes.empty() || options.terrain == TerrainOcclusion::OpenGL)
    renderer = std::make_unique<OsmesaDepthRenderer>();
  const double cell = std::min(scene.dx, scene.dy);
  HorizonSweeper sweeper(scene.ground, scene.dx, scene.dy);

  float total_weight = 0.0f;
  for (std::size_t k = 0; k < dirs.size(); ++k) {
    if (!progress(static_cast<double>(k) / dirs.size(), "snowfall depth maps")) throw Cancelled();
    const Vector3d w = dirs[k].toward_source;
    const float weight = dirs[k].weight;
    total_weight += weight;
    const TerrainOccluder occluder(scene, w, options.terrain, renderer.get(), sweeper);
    const ObjectMaps objects =
        object_maps(scene, geometry.boxes, LightFrame::toward(w), options, cell, renderer.get());
    const terrain::Grid<unsigned char> near_object =
        cells_near_objects(scene, geometry.boxes, w, objects);
    const int K =
        options.ground_samples > 0
            ? std::clamp(options.ground_samples, 1, 16)
            : std::clamp(static_cast<int>(std::ceil(cell / (2.0 * objects.finest))), 1, 8);
    accumulate_ground(scene, occluder, objects, near_object, w, weight, K, out.ground,
                      out.ground_facing);
    accumulate_faces(scene, geometry, occluder, objects, w, weight, out);
  }
  normalise(out, total_weight);
  progress(1.0, "snowfall depth maps");
  return out;
}

}  // namespace drift::snow
