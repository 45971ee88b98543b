#include "snow/snowfall_mesh_refine.h"

#include <unordered_map>

namespace drift::snow {

namespace {
std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}
using Midpoints = std::unordered_map<std::uint64_t, int>;

// The longest edge of every triangle with an edge longer than sqrt(max2),
// each given a new midpoint vertex (in a deterministic order). Empty when
// nothing is too long.
Midpoints split_longest_edges(terrain::Mesh& out, double max2) {
  Midpoints mid;
  std::vector<std::uint64_t> order;
  for (const auto& t : out.triangles) {
    int longest = -1;
    double best = max2;
    for (int e = 0; e < 3; ++e) {
      const double l2 = (out.positions[t[e]] - out.positions[t[(e + 1) % 3]]).squaredNorm();
      if (l2 > best) best = l2, longest = e;
    }
    if (longest < 0) continue;
    const auto key = edge_key(t[longest], t[(longest + 1) % 3]);
    if (mid.emplace(key, -1).second) order.push_back(key);
  }
  for (std::uint64_t key : order) {  // midpoints in a deterministic order
    const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
    mid[key] = static_cast<int>(out.positions.size());
    out.positions.push_back(0.5f * (out.positions[a] + out.positions[b]));
  }
  return mid;
}

// Triangle t with the midpoints of its split edges, as 1 to 4 triangles.
void split_triangle(std::array<int, 3> t, const Midpoints& mid,
                    std::vector<std::array<int, 3>>& next) {
  std::array<int, 3> m;
  int count = 0;
  for (int e = 0; e < 3; ++e) {
    const auto it = mid.find(edge_key(t[e], t[(e + 1) % 3]));
    m[e] = it == mid.end() ? -1 : it->second;
    count += m[e] >= 0;
  }
  // Rotate so that the split edges come first: 1 split -> edge 0; 2 -> edges 0, 1.
  for (int r = 0; r < 3 && count > 0 && count < 3; ++r) {
    const bool ok = count == 1 ? m[0] >= 0 : (m[0] >= 0 && m[1] >= 0);
    if (ok) break;
    t = {t[1], t[2], t[0]};
    m = {m[1], m[2], m[0]};
  }
  if (count == 0) {
    next.push_back(t);
  } else if (count == 1) {
    next.push_back({t[0], m[0], t[2]});
    next.push_back({m[0], t[1], t[2]});
  } else if (count == 2) {
    next.push_back({m[0], t[1], m[1]});
    next.push_back({t[0], m[0], m[1]});
    next.push_back({t[0], m[1], t[2]});
  } else {
    next.push_back({t[0], m[0], m[2]});
    next.push_back({m[0], t[1], m[1]});
    next.push_back({m[2], m[1], t[2]});
    next.push_back({m[0], m[1], m[2]});
  }
}

}  // namespace

terrain::Mesh refine_mesh(const terrain::Mesh& mesh, double max_edge) {
  terrain::Mesh out;
  out.positions = mesh.positions;
  out.triangles = mesh.triangles;
  if (max_edge <= 0.0) {
    out.normals = mesh.normals;
    out.vertex_attributes = mesh.vertex_attributes;
    return out;
  }
  const double max2 = max_edge * max_edge;
  for (int pass = 0; pass < 64; ++pass) {
    const Midpoints mid = split_longest_edges(out, max2);
    if (mid.empty()) break;
    std::vector<std::array<int, 3>> next;
    next.reserve(out.triangles.size() * 2);
    for (const auto& t : out.triangles) split_triangle(t, mid, next);
    out.triangles = std::move(next);
  }
  return out;
}

}  // namespace drift::snow
