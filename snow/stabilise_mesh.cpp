#include "snow/stabilise_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

#include "terrain/angles.h"
#include "terrain/error.h"

namespace drift::snow {

namespace {
constexpr double kNoFootprint = 1e-12;  // m^2: below this a vertex holds no snow

// The holding vertices' neighbours (CSR, each with the height difference
// that stands at the angle of repose over its horizontal distance) and which
// vertices border the holding region (snow falls off them).
struct SnowGraph {
  std::vector<std::size_t> start;
  std::vector<int> to;
  std::vector<double> reach;
  std::vector<unsigned char> edge_vertex;
};

template <class Holds>
SnowGraph snow_graph(const terrain::Mesh& mesh, const Holds& holds, double tan_r) {
  const std::size_t n = mesh.vertex_count();
  // Edges with the number of triangles using them (1: open border).
  std::map<std::pair<int, int>, int> edge_use;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      ++edge_use[{std::min(a, b), std::max(a, b)}];
    }
  std::vector<std::vector<int>> adj(n);
  SnowGraph g;
  g.edge_vertex.assign(n, 0);
  for (const auto& [e, uses] : edge_use) {
    const auto [a, b] = e;
    if (holds(a) && holds(b)) {
      adj[a].push_back(b);
      adj[b].push_back(a);
    }
    if (uses == 1 || !holds(a) || !holds(b)) g.edge_vertex[a] = g.edge_vertex[b] = 1;
  }
  g.start.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) g.start[i + 1] = g.start[i] + adj[i].size();
  g.to.resize(g.start[n]);
  g.reach.resize(g.start[n]);
  for (std::size_t i = 0; i < n; ++i) {
    std::sort(adj[i].begin(), adj[i].end());
    for (std::size_t k = 0; k < adj[i].size(); ++k) {
      const int j = adj[i][k];
      g.to[g.start[i] + k] = j;
      const Eigen::Vector3f d = mesh.positions[j] - mesh.positions[i];
      g.reach[g.start[i] + k] = tan_r * std::hypot(static_cast<double>(d.x()), d.y());
    }
  }
  return g;
}

// One vertex's step (the paper's three cases, with the virtual "falls off"
// neighbour of border vertices among the candidates): moves its excess over
// the angle of repose to lower neighbours and off the edge. Returns the
// volume that left it.
double relax_vertex(const terrain::Mesh& mesh, const SnowGraph& g,
                    const std::vector<double>& footprint, double tan_r, std::size_t i,
                    std::vector<double>& volume, std::vector<double>& flow, double& shed_out) {
  const double a = footprint[i], hi = mesh.positions[i].z() + volume[i] / a;
  double sum = 0.0, steepest = 0.0;
  for (std::size_t e = g.start[i]; e < g.start[i + 1]; ++e) {
    flow[e] = 0.0;
    const int j = g.to[e];
    const double ex = hi - (mesh.positions[j].z() + volume[j] / footprint[j]) - g.reach[e];
    if (ex <= 0.0) continue;
    const double q = ex / (1.0 / a + 1.0 / footprint[j]);
    flow[e] = q, sum += q, steepest = std::max(steepest, q);
  }
  double shed = 0.0;
  if (g.edge_vertex[i]) {
    const double ex = volume[i] / a - tan_r * 0.5 * std::sqrt(a);
    if (ex > 0.0) shed = ex * a, sum += shed, steepest = std::max(steepest, shed);
  }
  if (sum == 0.0) return 0.0;
  const double out = std::min(volume[i], steepest), scale = out / sum;
  for (std::size_t e = g.start[i]; e < g.start[i + 1]; ++e) {
    if (flow[e] <= 0.0) continue;
    volume[g.to[e]] += flow[e] * scale;
    volume[i] -= flow[e] * scale;
  }
  volume[i] -= shed * scale;
  shed_out += shed * scale;
  return out;
}

}  // namespace

std::vector<double> vertex_footprints(const terrain::Mesh& mesh) {
  std::vector<double> a(mesh.vertex_count(), 0.0);
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d p0 = mesh.positions[t[0]].cast<double>();
    const Eigen::Vector3d n =
        (mesh.positions[t[1]].cast<double>() - p0).cross(mesh.positions[t[2]].cast<double>() - p0);
    const double horizontal = 0.5 * n.z();  // signed projected area: > 0 faces up
    if (horizontal <= 0.0) continue;
    for (int k = 0; k < 3; ++k) a[t[k]] += horizontal / 3.0;
  }
  return a;
}

MeshStabiliseReport stabilise_mesh(const terrain::Mesh& mesh, const std::vector<double>& footprint,
                                   std::vector<double>& volume, const StabiliseOptions& options) {
  if (!(options.repose_deg > 0.0 && options.repose_deg < 90.0))
    throw Error("the angle of repose of snow must lie in (0, 90) degrees");
  const std::size_t n = mesh.vertex_count();
  const double tan_r = terrain::tan_degrees(options.repose_deg);
  // Slivers hold nothing: a footprint a million times below the mean would make
  // tiny volumes tall and keep them moving for ever.
  double mean = 0.0;
  std::size_t holding = 0;
  for (double a : footprint)
    if (a > kNoFootprint) mean += a, ++holding;
  mean = holding ? mean / holding : 0.0;
  const double threshold = std::max(kNoFootprint, 1e-6 * mean);
  auto holds = [&](std::size_t i) { return footprint[i] > threshold; };
  const SnowGraph graph = snow_graph(mesh, holds, tan_r);

  MeshStabiliseReport report;
  report.shed.assign(n, 0.0);
  if (n == 0) {
    report.converged = true;
    return report;
  }
  std::vector<double> flow(graph.start[n]);
  for (int it = 0; it < options.max_iterations; ++it) {
    // Vertex by vertex in index order, each seeing what the ones before it moved
    // (Gauss-Seidel): footprints differ a lot between vertices of a refined mesh, and
    // simultaneous (Jacobi) transfers into a small vertex from several large ones
    // overshoot. Sequential, hence independent of the thread count.
    double largest = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (volume[i] <= 0.0) continue;
      if (!holds(i)) {  // snow given to a sliver cannot stay there
        report.shed[i] += volume[i];
        largest = std::max(largest, volume[i]);
        volume[i] = 0.0;
        continue;
      }
      const double out =
          relax_vertex(mesh, graph, footprint, tan_r, i, volume, flow, report.shed[i]);
      largest = std::max(largest, out);
    }
    report.iterations = it + 1;
    if (largest <= options.tolerance * mean) {  // volume of `tolerance` m on a typical vertex
      report.converged = true;
      break;
    }
  }
  return report;
}

}  // namespace drift::snow
