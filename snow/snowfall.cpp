#include "snow/snowfall.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "snow/occlusion_blocks.h"
#include "snow/snowfall_directions.h"
#include "snow/snowfall_parameters.h"
#include "snow/stabilise_grid.h"
#include "snow/stabilise_mesh.h"
#include "terrain/error.h"
#include "terrain/memory.h"
#include "terrain/parameter.h"
#include "terrain/products.h"

namespace drift::snow {

namespace {

// Snow on one object: the polygon variant.
struct ObjectSnow {
  std::vector<double> footprint;  // horizontal area each vertex stands for (m^2)
  std::vector<double> volume;     // m^3 of snow a vertex holds
  std::vector<double> depth, probability, adhesion;
  double fallen = 0, kept = 0;
};

// Paper 2.3(1)-(2): each face's snow (probability x amount over its
// horizontal area) shared among its vertices, the vertex probability as the
// mean of its faces' and the adhesion of steep faces.
ObjectSnow fall_on_object(const terrain::Mesh& m, const std::vector<float>& face_probability,
                          const std::vector<float>& face_facing, double amount,
                          const CoverageOptions& coverage) {
  ObjectSnow os;
  os.footprint = vertex_footprints(m);
  os.volume.assign(m.vertex_count(), 0.0);
  std::vector<double> face_count(m.vertex_count(), 0.0);
  os.probability.assign(m.vertex_count(), 0.0);
  os.adhesion.assign(m.vertex_count(), 0.0);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const auto& tri = m.triangles[t];
    const Eigen::Vector3d p0 = m.positions[tri[0]].cast<double>();
    const Eigen::Vector3d cross =
        (m.positions[tri[1]].cast<double>() - p0).cross(m.positions[tri[2]].cast<double>() - p0);
    const double horizontal = std::max(0.0, 0.5 * cross.z());
    const Eigen::Vector3d n =
        cross.norm() > 0 ? Eigen::Vector3d(cross.normalized()) : Eigen::Vector3d::UnitZ();
    const double adhesion = adhesion_coverage(n, face_facing[t], amount, coverage);
    for (int k = 0; k < 3; ++k) {
      os.volume[tri[k]] += horizontal / 3.0 * face_probability[t] * amount;
      os.probability[tri[k]] += face_probability[t];
      os.adhesion[tri[k]] += adhesion;
      face_count[tri[k]] += 1.0;
    }
  }
  for (std::size_t i = 0; i < m.vertex_count(); ++i) {
    os.fallen += os.volume[i];
    if (face_count[i] > 0) os.adhesion[i] /= face_count[i];
    // Paper 2.3(2): a vertex's probability is the mean of its faces'; where the
    // vertex holds snow, weighted by the footprint each face gives it.
    os.probability[i] = os.footprint[i] > 0 ? os.volume[i] / (os.footprint[i] * amount)
                        : face_count[i] > 0 ? os.probability[i] / face_count[i]
                                            : 0.0;
  }
  return os;
}

// Paper 2.3(3): stabilises an object's snow along its mesh; what falls off
// lands on the ground cell below (`snow`, m) or, off the raster, is lost.
void settle_object(const SnowScene& scene, const terrain::Mesh& m,
                   const StabiliseOptions& stabilise, ObjectSnow& os, terrain::Grid<double>& snow,
                   SnowfallResult& result) {
  const int W = scene.ground.width(), H = scene.ground.height();
  const double cell_area = scene.dx * scene.dy;
  const MeshStabiliseReport r = stabilise_mesh(m, os.footprint, os.volume, stabilise);
  result.object_iterations = std::max(result.object_iterations, r.iterations);
  result.converged = result.converged && r.converged;
  os.depth.assign(m.vertex_count(), 0.0);
  for (std::size_t i = 0; i < m.vertex_count(); ++i) {
    if (os.footprint[i] > 0) os.depth[i] = os.volume[i] / os.footprint[i];
    os.kept += os.volume[i];
    if (r.shed[i] <= 0) continue;
    result.shed_volume += r.shed[i];
    const int col = static_cast<int>(std::lround(scene.col_of(m.positions[i].x())));
    const int row = static_cast<int>(std::lround(scene.row_of(m.positions[i].y())));
    if (col < 0 || row < 0 || col >= W || row >= H) {
      result.lost_volume += r.shed[i];
    } else {
      snow(col, row) += r.shed[i] / cell_area;
    }
  }
}

// The depth and coverage rasters, NaN where the ground had no data.
void write_ground_rasters(const terrain::HeightField& ground, const SnowScene& scene,
                          const terrain::Grid<double>& snow, const terrain::Grid<float>& facing,
                          double amount, const CoverageOptions& coverage, SnowfallResult& result) {
  const int W = ground.width(), H = ground.height();
  result.depth = terrain::HeightField(W, H, 0.0f, ground.geo());
  result.coverage = terrain::HeightField(W, H, 0.0f, ground.geo());
  tbb::parallel_for(0, H, [&](int row) {
    for (int col = 0; col < W; ++col) {
      if (std::isnan(ground(col, row))) {
        result.depth(col, row) = result.coverage(col, row) = std::nanf("");
        continue;
      }
      const double d = snow(col, row);
      result.depth(col, row) = static_cast<float>(std::max(d, 0.0));  // -1e-16 from rounding
      const double stuck =
          adhesion_coverage(scene.ground_normal(col, row), facing(col, row), amount, coverage);
      result.coverage(col, row) = static_cast<float>(std::max(thin_coverage(d, coverage), stuck));
    }
  });
}

// One mesh of all objects, raised by their snow (paper 2.3(4)), relative to
// a whole-metre origin, with the per-vertex attributes of SnowfallResult.
void write_snowy_objects(const SnowScene& scene, const std::vector<ObjectSnow>& object_snow,
                         const CoverageOptions& coverage, SnowfallResult& result) {
  result.mesh_origin =
      Eigen::Vector3d(std::round(scene.origin.x()), std::round(scene.origin.y()), 0.0);
  const Eigen::Vector3d shift = scene.origin - result.mesh_origin;
  result.objects.origin = result.mesh_origin;
  std::vector<float> a_depth, a_prob, a_cover, a_adhesion, a_object;
  for (std::size_t o = 0; o < scene.meshes.size(); ++o) {
    const terrain::Mesh& m = scene.meshes[o];
    const ObjectSnow& os = object_snow[o];
    const int base = static_cast<int>(result.objects.positions.size());
    for (std::size_t i = 0; i < m.vertex_count(); ++i) {
      Eigen::Vector3d p = m.positions[i].cast<double>() + shift;
      p.z() += os.depth[i];
      result.objects.positions.push_back(p.cast<float>());
      a_depth.push_back(static_cast<float>(os.depth[i]));
      a_prob.push_back(static_cast<float>(os.probability[i]));
      a_adhesion.push_back(static_cast<float>(os.adhesion[i]));
      a_object.push_back(static_cast<float>(o));
      a_cover.push_back(
          static_cast<float>(std::max(thin_coverage(os.depth[i], coverage), os.adhesion[i])));
    }
    for (auto t : m.triangles)
      result.objects.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  namespace products = terrain::products;
  result.objects.vertex_attributes = {{products::kSnowDepth, std::move(a_depth)},
                                      {products::kSnowProbability, std::move(a_prob)},
                                      {products::kSnowCoverage, std::move(a_cover)},
                                      {products::kSnowAdhesion, std::move(a_adhesion)},
                                      {products::kObjectIndex, std::move(a_object)}};
}

}  // namespace

// The ranges live in one table (snow/snowfall_parameters.toml).
void SnowfallOptions::validate() const {
  for (const SnowfallParameter& p : snowfall_parameters()) p.require(*this);
}

SnowfallResult simulate_snowfall(const terrain::HeightField& ground,
                                 const std::vector<terrain::PlacedMesh>& objects,
                                 const SnowfallOptions& options, const ProgressFn& progress) {
  options.validate();
  const ProgressFn report = progress ? progress : ProgressFn(no_progress);
  if (!report(0.0, "snowfall")) throw Cancelled();
  // Ground copy, probability (+ facing), depth as double and the passes' double
  // buffer (not with --stabilise direct, which counts its own), output rasters.
  require_memory(ground.size() * (4 + 8 + 8 + 8 + (options.direct_stabilise ? 0 : 8) + 4 + 4),
                 "snowfall on the ground raster", "crop or resample the ground raster");
  const SnowScene scene = make_snow_scene(ground, objects, options.mesh_max_edge);
  const auto dirs = jittered_directions(options.azimuth_deg, options.elevation_deg,
                                        options.spread_deg, options.maps, options.seed);
  const bool blocks = options.block > 0 && scene.meshes.empty() &&
                      options.occlusion.terrain == TerrainOcclusion::Sweep;
  SnowProbability prob =
      blocks ? ground_probability_in_blocks(scene, dirs, options.block, options.occlusion)
             : snow_probability(scene, dirs, options.occlusion, scaled_progress(report, 0.0, 0.6));
  const double amount = options.rate_m_per_h * options.hours;  // m on open flat ground
  const double cell_area = scene.dx * scene.dy;
  StabiliseOptions stabilise{options.repose_deg, options.tolerance, options.max_iterations};
  SnowfallResult result;

  // Fresh snow on the ground (paper 2.2(2)): probability x rate x time.
  terrain::Grid<double> snow(scene.ground.width(), scene.ground.height(), 0.0);
  for (std::size_t i = 0; i < snow.size(); ++i)
    snow.values()[i] = static_cast<double>(prob.ground.values()[i]) * amount;
  for (double v : snow.values()) result.fallen_volume += v * cell_area;

  // Objects (paper 2.3): per-vertex snow from the faces, stabilised along the mesh;
  // what falls off lands on the ground cell below.
  std::vector<ObjectSnow> object_snow;
  for (std::size_t o = 0; o < scene.meshes.size(); ++o) {
    ObjectSnow& os = object_snow.emplace_back(
        fall_on_object(scene.meshes[o], prob.faces[o], prob.facing[o], amount, options.coverage));
    result.fallen_volume += os.fallen;
    settle_object(scene, scene.meshes[o], stabilise, os, snow, result);
    result.object_volume += os.kept;
  }
  if (!report(0.65, "snow on objects")) throw Cancelled();

  // Ground (paper 2.2(3)).
  StabiliseOptions ground_rule = stabilise;
  ground_rule.tolerance = options.ground_tolerance;
  ground_rule.coarse_levels = options.coarse_levels;
  ground_rule.direct = options.direct_stabilise;
  ground_rule.direct_layers = options.direct_layers;
  // Alive beside stabilisation: the ground, the probability and its facing
  // (4 B a cell each) and the snow (8): 20 B a cell, 54.8 measured with the
  // passes' 34 (MemoryEstimate.SnowFallOnGroundThatNeverSlides).
  ground_rule.held_bytes_per_cell = 20;
  const StabiliseReport gr = stabilise_grid(scene.ground, snow, scene.dx, scene.dy, ground_rule,
                                            scaled_progress(report, 0.65, 0.95));
  result.ground_iterations = gr.iterations;
  result.converged = result.converged && gr.converged;
  for (double v : snow.values()) result.ground_volume += v * cell_area;

  write_ground_rasters(ground, scene, snow, prob.ground_facing, amount, options.coverage, result);
  write_snowy_objects(scene, object_snow, options.coverage, result);
  report(1.0, "snowfall");
  return result;
}

}  // namespace drift::snow
