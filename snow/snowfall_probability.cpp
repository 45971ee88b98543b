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

}  // namespace

SnowProbability snow_probability(const SnowScene& scene, const std::vector<FallDirection>& dirs,
                                 const ProbabilityOptions& options, const ProgressFn& progress) {
  const int W = scene.ground.width(), H = scene.ground.height();
  SnowProbability out;
  terrain::Grid<float> acc(W, H, 0.0f), acc_facing(W, H, 0.0f);
  const std::size_t n_objects = scene.meshes.size();
  std::vector<std::vector<float>> face_acc(n_objects), face_facing(n_objects);
  std::vector<Box> boxes;
  std::vector<std::vector<Vector3d>> face_normals(n_objects);
  for (std::size_t o = 0; o < n_objects; ++o) {
    const terrain::Mesh& m = scene.meshes[o];
    boxes.push_back(mesh_box(m));
    face_acc[o].assign(m.triangle_count(), 0.0f);
    face_facing[o].assign(m.triangle_count(), 0.0f);
    face_normals[o].resize(m.triangle_count());
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const auto& tri = m.triangles[t];
      const Vector3d a = m.positions[tri[0]].cast<double>(), b = m.positions[tri[1]].cast<double>(),
                     c = m.positions[tri[2]].cast<double>();
      const Vector3d n = (b - a).cross(c - a);
      face_normals[o][t] = n.norm() > 0 ? Vector3d(n.normalized()) : Vector3d::Zero();
    }
  }
  std::unique_ptr<OsmesaDepthRenderer> renderer;
  if (n_objects > 0 || options.terrain == TerrainOcclusion::OpenGL)
    renderer = std::make_unique<OsmesaDepthRenderer>();
  const double cell = std::min(scene.dx, scene.dy);
  HorizonSweeper sweeper(scene.ground, scene.dx, scene.dy);

  float total_weight = 0.0f;
  for (std::size_t k = 0; k < dirs.size(); ++k) {
    if (!progress(static_cast<double>(k) / dirs.size(), "snowfall depth maps")) throw Cancelled();
    const Vector3d w = dirs[k].toward_source;
    const float weight = dirs[k].weight;
    total_weight += weight;
    const LightFrame frame = LightFrame::toward(w);
    const TerrainOccluder terrain_occluder(scene, w, options.terrain, renderer.get(), sweeper);

    // Object maps: one around each object, holding every object that overlaps it.
    std::vector<DepthMap> maps(n_objects);
    std::vector<Rect> rects(n_objects);
    for (std::size_t o = 0; o < n_objects; ++o) rects[o] = project_box(frame, boxes[o]);
    double finest = cell;
    for (std::size_t o = 0; o < n_objects; ++o) {
      const Rect& r = rects[o];
      const double extent = std::max({r.a_hi - r.a_lo, r.b_hi - r.b_lo, 1e-3});
      const double texel =
          options.object_texel > 0 ? options.object_texel : std::min(0.5 * cell, extent / 1024.0);
      maps[o].frame = frame;
      frame_map(maps[o], r, texel);
      finest = std::min(finest, maps[o].texel);
      std::vector<const terrain::Mesh*> drawn;
      double c_lo = r.c_lo, c_hi = r.c_hi;
      for (std::size_t q = 0; q < n_objects; ++q) {
        if (!rects[q].overlaps(r)) continue;
        drawn.push_back(&scene.meshes[q]);
        c_lo = std::min(c_lo, rects[q].c_lo), c_hi = std::max(c_hi, rects[q].c_hi);
      }
      renderer->render(maps[o], c_lo, c_hi, drawn, nullptr);
    }
    auto objects_lit = [&](const Vector3d& p, const Vector3d& n) {
      const Vector3d q = frame.project(p);
      for (const DepthMap& m : maps)
        if (m.contains(q.x(), q.y()) && !m.lit(p, n)) return false;
      return true;
    };

    // Ground cells that objects may shade: sampled K x K.
    terrain::Grid<unsigned char> near_object(W, H, 0);
    for (std::size_t o = 0; o < n_objects; ++o) {
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
      const double margin = std::hypot(scene.dx, scene.dy) + 2 * maps[o].texel;
      const Rect& r = rects[o];
      for (int row = r0; row <= r1; ++row)
        for (int col = c0; col <= c1; ++col) {
          const Vector3d q = frame.project(scene.cell_point(col, row));
          if (q.x() >= r.a_lo - margin && q.x() <= r.a_hi + margin && q.y() >= r.b_lo - margin &&
              q.y() <= r.b_hi + margin)
            near_object(col, row) = 1;
        }
    }
    const int K = options.ground_samples > 0
                      ? std::clamp(options.ground_samples, 1, 16)
                      : std::clamp(static_cast<int>(std::ceil(cell / (2.0 * finest))), 1, 8);

    // Cells in 64 x 64 blocks: a transposed shadow surface reads well within a block.
    constexpr int B = 64;
    tbb::parallel_for(
        tbb::blocked_range2d<int>(0, (H + B - 1) / B, 0, (W + B - 1) / B),
        [&](const tbb::blocked_range2d<int>& blocks) {
          for (int by = blocks.rows().begin(); by < blocks.rows().end(); ++by)
            for (int bx = blocks.cols().begin(); bx < blocks.cols().end(); ++bx)
              for (int row = by * B; row < std::min(H, (by + 1) * B); ++row)
                for (int col = bx * B; col < std::min(W, (bx + 1) * B); ++col) {
                  float lit = 0.0f;
                  double cos_phi;
                  if (!near_object(col, row)) {
                    cos_phi = scene.ground_normal(col, row).dot(w);
                    lit = terrain_occluder.cell_lit(col, row, cos_phi) ? 1.0f : 0.0f;
                  } else {
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
                                              ? terrain_occluder.cell_lit(col, row, cos_phi)
                                              : cos_phi > 0 && terrain_occluder.point_lit(p, n);
                        count += seen && objects_lit(p, n);
                      }
                    lit = static_cast<float>(count) / static_cast<float>(K * K);
                  }
                  acc(col, row) += weight * lit;
                  acc_facing(col, row) += weight * lit * static_cast<float>(std::max(0.0, cos_phi));
                }
        });

    for (std::size_t o = 0; o < n_objects; ++o) {
      const terrain::Mesh& m = scene.meshes[o];
      tbb::parallel_for(std::size_t{0}, m.triangle_count(), [&](std::size_t t) {
        const Vector3d& n = face_normals[o][t];
        const double facing = n.dot(w);
        if (facing <= 0.0) return;
        const auto& tri = m.triangles[t];
        int count = 0;
        for (const Vector3d& p :
             face_samples(m.positions[tri[0]].cast<double>(), m.positions[tri[1]].cast<double>(),
                          m.positions[tri[2]].cast<double>()))
          count += terrain_occluder.point_lit(p, n) && objects_lit(p, n);
        const float lit = static_cast<float>(count) / 4.0f;
        face_acc[o][t] += weight * lit;
        face_facing[o][t] += weight * lit * static_cast<float>(facing);
      });
    }
  }
  // Normalise by the same float sum of weights: a point lit in every map gets exactly 1.
  for (auto* g : {&acc, &acc_facing})
    for (float& v : g->values()) v /= total_weight;
  for (std::size_t o = 0; o < n_objects; ++o) {
    for (float& v : face_acc[o]) v /= total_weight;
    for (float& v : face_facing[o]) v /= total_weight;
  }
  out.ground = std::move(acc);
  out.ground_facing = std::move(acc_facing);
  out.faces = std::move(face_acc);
  out.facing = std::move(face_facing);
  progress(1.0, "snowfall depth maps");
  return out;
}

}  // namespace drift::snow
