#include "terrain/marks/object_geometry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "terrain/error.h"

namespace drift::marks {

GridFrame GridFrame::of(const terrain::GeoReference& geo) {
  if (!geo.north_up()) throw Error("marks need a north-up ground raster (no rotation terms)");
  const auto& gt = geo.geotransform;
  return {gt[0] + 0.5 * gt[1], gt[3] + 0.5 * gt[5], gt[1], -gt[5]};
}

ObjectShape ObjectShape::of(terrain::Mesh mesh) {
  ObjectShape s;
  s.normals.assign(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.positions[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.positions[t[2]].cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a);  // twice the area, outward
    for (int k : t) s.normals[k] += n;
  }
  for (auto& n : s.normals) {
    const double len = n.norm();
    if (len > 0) n /= len;
  }
  for (const auto& p : mesh.positions) s.radius = std::max(s.radius, p.cast<double>().norm());
  s.mesh = std::move(mesh);
  return s;
}

CellTriangles posed_triangles(const ObjectShape& shape, const Pose& pose, const GridFrame& frame) {
  const Eigen::Matrix3d r = pose.rotation.toRotationMatrix();
  std::vector<Eigen::Vector3d> v(shape.mesh.positions.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = frame.to_cell(pose.position + r * shape.mesh.positions[i].cast<double>());
  CellTriangles out;
  out.reserve(shape.mesh.triangles.size() * 3);
  for (const auto& t : shape.mesh.triangles)
    for (int k : t) out.push_back(v[k]);
  return out;
}

namespace {

enum class Side { Current, Previous, Swept };

// Paper 000, 3.3: the signs of n.d at a triangle's vertices.
Side classify(double s0, double s1, double s2, double eps) {
  const int pos = (s0 > eps) + (s1 > eps) + (s2 > eps);
  const int neg = (s0 < -eps) + (s1 < -eps) + (s2 < -eps);
  if (pos == 3) return Side::Current;
  if (pos > 0 && neg > 0) return Side::Swept;    // (1) both signs
  if (pos == 0 && neg == 0) return Side::Swept;  // (2) all zero
  if (neg == 0) return Side::Swept;              // (3) positive and zero
  return Side::Previous;
}

void push_triangle(CellTriangles& out, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                   const Eigen::Vector3d& c) {
  out.push_back(a), out.push_back(b), out.push_back(c);
}

// The prism a triangle sweeps: both caps and the three sides (two triangles each).
void push_prism(CellTriangles& out, const std::array<Eigen::Vector3d, 3>& p,
                const std::array<Eigen::Vector3d, 3>& q) {
  push_triangle(out, p[0], p[1], p[2]);
  push_triangle(out, q[0], q[1], q[2]);
  for (int k = 0; k < 3; ++k) {
    const int l = (k + 1) % 3;
    push_triangle(out, p[k], p[l], q[l]);
    push_triangle(out, p[k], q[l], q[k]);
  }
}

}  // namespace

CellTriangles swept_triangles(const ObjectShape& shape, const Eigen::Vector3d& from, const Pose& to,
                              const GridFrame& frame) {
  const Eigen::Matrix3d r = to.rotation.toRotationMatrix();
  const Eigen::Vector3d d = to.position - from;
  const std::size_t n = shape.mesh.positions.size();
  std::vector<Eigen::Vector3d> now(n), before(n);
  std::vector<double> s(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d local = r * shape.mesh.positions[i].cast<double>();
    now[i] = frame.to_cell(to.position + local);
    before[i] = frame.to_cell(from + local);
    s[i] = (r * shape.normals[i]).dot(d);
  }
  const double eps = 1e-9 * d.norm();
  CellTriangles out;
  out.reserve(shape.mesh.triangles.size() * 6);
  for (const auto& t : shape.mesh.triangles) {
    switch (classify(s[t[0]], s[t[1]], s[t[2]], eps)) {
      case Side::Current:
        push_triangle(out, now[t[0]], now[t[1]], now[t[2]]);
        break;
      case Side::Previous:
        push_triangle(out, before[t[0]], before[t[1]], before[t[2]]);
        break;
      case Side::Swept:
        push_prism(out, {before[t[0]], before[t[1]], before[t[2]]},
                   {now[t[0]], now[t[1]], now[t[2]]});
        break;
    }
  }
  return out;
}

}  // namespace drift::marks
