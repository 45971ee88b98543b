#include "terrain/soil/primitives.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "terrain/error.h"
#include "terrain/soil/solid_mesh.h"

namespace drift::soil {

using Eigen::Vector3d;

bool Primitive::inside(const Vector3d& p) const {
  const Vector3d q = p - center;
  switch (kind) {
    case PrimitiveKind::Sphere:
      return q.squaredNorm() <= size.x() * size.x();
    case PrimitiveKind::Ellipsoid:
      return q.cwiseQuotient(size).squaredNorm() <= 1.0;
    case PrimitiveKind::Cuboid:
      return (q.cwiseAbs().array() <= size.array()).all();
    case PrimitiveKind::Cylinder:
      return std::abs(q.z()) <= size.z() && q.x() * q.x() + q.y() * q.y() <= size.x() * size.x();
    case PrimitiveKind::Cone: {
      if (q.z() < 0 || q.z() > size.z()) return false;
      const double r = size.x() * (1.0 - q.z() / size.z());
      return q.x() * q.x() + q.y() * q.y() <= r * r;
    }
  }
  return false;
}

namespace {
double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}
}  // namespace

bool Primitive::misses_ball(const Vector3d& p, double r) const {
  const Vector3d q = p - center;
  switch (kind) {
    case PrimitiveKind::Sphere:
      return q.norm() > size.x() + r;
    case PrimitiveKind::Ellipsoid:
      // |x / s| >= 1 + r / min(s) gives |(q + d) / s| >= 1 for |d| <= r.
      return q.cwiseQuotient(size).norm() > 1.0 + r / size.minCoeff();
    case PrimitiveKind::Cuboid:
      return (q.cwiseAbs() - size).cwiseMax(0.0).norm() > r;
    case PrimitiveKind::Cylinder:
      return Eigen::Vector2d(std::max(0.0, std::hypot(q.x(), q.y()) - size.x()),
                             std::max(0.0, std::abs(q.z()) - size.z()))
                 .norm() > r;
    case PrimitiveKind::Cone: {
      // The cone's half-section in (radius, height): a triangle.
      const Eigen::Vector2d x(std::hypot(q.x(), q.y()), q.z());
      if (x.y() >= 0 && x.y() <= size.z() && x.x() <= size.x() * (1.0 - x.y() / size.z()))
        return false;
      const Eigen::Vector2d o(0, 0), base(size.x(), 0), apex(0, size.z());
      return std::min({segment_distance(x, o, base), segment_distance(x, base, apex),
                       segment_distance(x, o, apex)}) > r;
    }
  }
  return false;
}

bool Primitive::holds_ball(const Vector3d& p, double r) const {
  const Vector3d q = p - center;
  switch (kind) {
    case PrimitiveKind::Sphere:
      return q.norm() + r <= size.x();
    case PrimitiveKind::Cuboid:
      return (q.cwiseAbs().array() + r <= size.array()).all();
    case PrimitiveKind::Cylinder:
      return std::abs(q.z()) + r <= size.z() && std::hypot(q.x(), q.y()) + r <= size.x();
    default:
      return false;
  }
}

Vector3d Primitive::lower() const {
  switch (kind) {
    case PrimitiveKind::Sphere:
      return center - Vector3d::Constant(size.x());
    case PrimitiveKind::Cylinder:
      return center - Vector3d(size.x(), size.x(), size.z());
    case PrimitiveKind::Cone:
      return center - Vector3d(size.x(), size.x(), 0.0);
    default:
      return center - size;
  }
}

Vector3d Primitive::upper() const {
  switch (kind) {
    case PrimitiveKind::Sphere:
      return center + Vector3d::Constant(size.x());
    case PrimitiveKind::Cylinder:
    case PrimitiveKind::Cone:  // both reach size.z() above the centre (the cone's base)
      return center + Vector3d(size.x(), size.x(), size.z());
    default:
      return center + size;
  }
}

namespace {

const char* kind_name(PrimitiveKind k) {
  switch (k) {
    case PrimitiveKind::Sphere:
      return "sphere";
    case PrimitiveKind::Ellipsoid:
      return "ellipsoid";
    case PrimitiveKind::Cuboid:
      return "cuboid";
    case PrimitiveKind::Cylinder:
      return "cylinder";
    case PrimitiveKind::Cone:
      return "cone";
  }
  return "?";
}

// Which components of `size` a kind uses.
bool uses(PrimitiveKind k, int axis) {
  if (k == PrimitiveKind::Sphere) return axis == 0;
  if (k == PrimitiveKind::Cylinder || k == PrimitiveKind::Cone) return axis != 1;
  return true;
}

double overlap(double lo, double hi, double a, double b) {
  return std::max(0.0, std::min(hi, b) - std::max(lo, a)) / (hi - lo);
}

bool holds_box(const Primitive& p, const Vector3d& lo, const Vector3d& hi) {
  for (int c = 0; c < 8; ++c) {
    const Vector3d corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(),
                          (c & 4) ? hi.z() : lo.z());
    if (!p.inside(corner)) return false;
  }
  return true;
}

bool box_touches(const Primitive& p, const Vector3d& lo, const Vector3d& hi) {
  return (p.lower().array() < hi.array()).all() && (p.upper().array() > lo.array()).all();
}

}  // namespace

Vector3d RigidObject::position(double t) const {
  if (path.empty()) return Vector3d::Zero();
  if (t <= path.front().time) return path.front().position;
  if (t >= path.back().time) return path.back().position;
  auto it = std::upper_bound(path.begin(), path.end(), t,
                             [](double v, const Keyframe& k) { return v < k.time; });
  const Keyframe& b = *it;
  const Keyframe& a = *(it - 1);
  const double s = (t - a.time) / (b.time - a.time);
  return a.position + s * (b.position - a.position);
}

bool RigidObject::moves() const { return path.size() > 1 || spin != Vector3d::Zero(); }

namespace {
// The keyframe segment holding t: (a, b, s in [0, 1]); a == b at the ends.
struct Segment {
  const Keyframe *a, *b;
  double s;
};
Segment segment_at(const std::vector<Keyframe>& path, double t) {
  if (t <= path.front().time) return {&path.front(), &path.front(), 0.0};
  if (t >= path.back().time) return {&path.back(), &path.back(), 0.0};
  auto it = std::upper_bound(path.begin(), path.end(), t,
                             [](double v, const Keyframe& k) { return v < k.time; });
  return {&*(it - 1), &*it, (t - (it - 1)->time) / (it->time - (it - 1)->time)};
}

Eigen::Quaterniond spun(const Vector3d& spin, double t) {
  const double angle = spin.norm() * t;
  return angle == 0 ? Eigen::Quaterniond::Identity()
                    : Eigen::Quaterniond(Eigen::AngleAxisd(angle, spin.normalized()));
}
}  // namespace

Eigen::Quaterniond RigidObject::orientation(double t) const {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  if (!path.empty()) {
    const Segment g = segment_at(path, t);
    q = g.a->orientation.slerp(g.s, g.b->orientation);
  }
  return (spun(spin, t) * q).normalized();
}

Vector3d RigidObject::angular_velocity(double t) const {
  Vector3d w(0, 0, 0);
  if (path.size() >= 2 && t >= path.front().time && t < path.back().time) {
    const Segment g = segment_at(path, t);
    // R_b = dq R_a: dq's axis (world) times its angle over the segment's time.
    const Eigen::AngleAxisd dq(g.b->orientation * g.a->orientation.inverse());
    w = spun(spin, t) * (dq.axis() * dq.angle() / (g.b->time - g.a->time));
  }
  return w + spin;
}

Pose RigidObject::pose(double t) const { return {position(t), orientation(t).toRotationMatrix()}; }

PlacedSolid placed(const RigidObject& b, double t) {
  return {&b.primitives, b.mesh.get(), b.pose(t)};
}

Vector3d RigidObject::velocity(double t) const {
  if (path.size() < 2 || t < path.front().time || t >= path.back().time) return Vector3d::Zero();
  auto it = std::upper_bound(path.begin(), path.end(), t,
                             [](double v, const Keyframe& k) { return v < k.time; });
  const Keyframe& b = *it;
  const Keyframe& a = *(it - 1);
  return (b.position - a.position) / (b.time - a.time);
}

void validate(const RigidObject& o, const std::string& what) {
  if (o.primitives.empty() && !o.mesh)
    throw Error(what + " '" + o.name + "' has no primitives and no mesh");
  if (!o.spin.allFinite()) throw Error(what + " '" + o.name + "' has a non-finite spin");
  for (std::size_t i = 0; i < o.primitives.size(); ++i) {
    const Primitive& p = o.primitives[i];
    const std::string where = what + " '" + o.name + "' primitive " + std::to_string(i + 1) + " (" +
                              kind_name(p.kind) + ")";
    if (!p.center.allFinite()) throw Error(where + " has a non-finite centre");
    for (int a = 0; a < 3; ++a)
      if (uses(p.kind, a) && !(std::isfinite(p.size[a]) && p.size[a] > 0))
        throw Error(where + " has size " + std::to_string(p.size[a]) +
                    "; sizes must be positive finite metres");
  }
  for (std::size_t i = 0; i < o.path.size(); ++i) {
    if (!o.path[i].position.allFinite() || !std::isfinite(o.path[i].time) ||
        !o.path[i].orientation.coeffs().allFinite())
      throw Error(what + " '" + o.name + "' keyframe " + std::to_string(i + 1) + " is not finite");
    if (i > 0 && !(o.path[i].time > o.path[i - 1].time))
      throw Error(what + " '" + o.name + "' keyframe " + std::to_string(i + 1) +
                  " is not later than the one before; keyframe times must increase");
  }
}

namespace {
// The share of the box [lo, hi] that `inside` holds, sampled at the centres
// of 4 x 4 x 4 sub-boxes (where a box is not wholly in or out).
template <class Inside>
double sampled_share(const Vector3d& lo, const Vector3d& hi, const Inside& inside) {
  constexpr int n = 4;
  int in = 0;
  const Vector3d step = (hi - lo) / n;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        in += inside(lo + step.cwiseProduct(Vector3d(i + 0.5, j + 0.5, k + 0.5)));
  return static_cast<double>(in) / (n * n * n);
}

using Polygon = std::vector<Vector3d>;

// Keeps the part of each face of a convex polyhedron with q[axis] * side <=
// bound and closes the cut with a cap face (outward, counter-clockwise seen
// from outside). Faces are counter-clockwise seen from outside.
void clip_polyhedron(std::vector<Polygon>& faces, int axis, double side, double bound) {
  // Wholly inside the plane (every corner strictly): the loop below would
  // keep every face as it is and find no cap, so nothing to do. Most of a
  // boundary voxel's six planes do not cut it, and building the copies was
  // most of a turned blade's coverage (issue 33's follow-up).
  bool cuts = false;
  for (const Polygon& f : faces)
    for (const Vector3d& a : f) cuts = cuts || side * a[axis] - bound >= 0;
  if (!cuts) return;
  std::vector<Polygon> kept;
  Polygon cut;  // the points on the plane: the cap's corners
  for (const Polygon& f : faces) {
    Polygon out;
    for (std::size_t i = 0; i < f.size(); ++i) {
      const Vector3d& a = f[i];
      const Vector3d& b = f[(i + 1) % f.size()];
      const double da = side * a[axis] - bound, db = side * b[axis] - bound;
      if (da <= 0) out.push_back(a);
      if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
        Vector3d m = a + (b - a) * (da / (da - db));
        m[axis] = side * bound;  // on the plane exactly
        out.push_back(m);
        cut.push_back(m);
      } else if (da == 0) {
        cut.push_back(a);
      }
    }
    if (out.size() >= 3) kept.push_back(std::move(out));
  }
  if (cut.size() >= 3) {
    // Counter-clockwise about the outward normal side * e_axis: (u, v, n)
    // right-handed.
    const int u = side > 0 ? (axis + 1) % 3 : (axis + 2) % 3;
    const int v = side > 0 ? (axis + 2) % 3 : (axis + 1) % 3;
    Vector3d mid = Vector3d::Zero();
    for (const Vector3d& p : cut) mid += p;
    mid /= static_cast<double>(cut.size());
    // Each corner's angle once (the sort's comparisons called atan2 twice
    // each: a third of a turned blade's coverage); sorting their indices by
    // the same keys makes the same comparisons, so the same order.
    std::vector<double> angle(cut.size());
    std::vector<int> order(cut.size());
    for (std::size_t k = 0; k < cut.size(); ++k) {
      angle[k] = std::atan2(cut[k][v] - mid[v], cut[k][u] - mid[u]);
      order[k] = static_cast<int>(k);
    }
    std::sort(order.begin(), order.end(), [&](int a, int b) { return angle[a] < angle[b]; });
    Polygon cap(cut.size());
    for (std::size_t k = 0; k < cut.size(); ++k) cap[k] = cut[order[k]];
    kept.push_back(std::move(cap));
  }
  faces = std::move(kept);
}

// Volume of a closed polyhedron of outward faces (divergence theorem: a fan
// of tetrahedra from the origin over every face).
double polyhedron_volume(const std::vector<Polygon>& faces) {
  double v = 0;
  for (const Polygon& f : faces)
    for (std::size_t i = 1; i + 1 < f.size(); ++i) v += f[0].dot(f[i].cross(f[i + 1]));
  return v / 6.0;
}

// Exact share of the world box [lo, hi] inside one cuboid of a turned body
// (issue 33's follow-up: a turning blade's coverage was sampled 4 x 4 x 4):
// the box, turned into the body's frame, is a convex polyhedron; clipped by
// the cuboid's six planes it is their intersection, whose volume the
// divergence theorem gives. Coordinates relative to the box's centre, so
// the sums keep double precision.
double cuboid_share(const Primitive& p, const Pose& pose, const Vector3d& lo, const Vector3d& hi) {
  const Vector3d mid = 0.5 * (lo + hi);
  const Vector3d centre = p.center - pose.to_body(mid);  // the cuboid's, from the box's centre
  Vector3d c[8];
  for (int k = 0; k < 8; ++k) {
    const Vector3d w((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(),
                     (k & 4) ? hi.z() : lo.z());
    c[k] = pose.rotation.transpose() * (w - mid);
  }
  // The box's faces, counter-clockwise seen from outside (a rotation keeps that).
  std::vector<Polygon> faces = {{c[0], c[4], c[6], c[2]}, {c[1], c[3], c[7], c[5]},
                                {c[0], c[1], c[5], c[4]}, {c[2], c[6], c[7], c[3]},
                                {c[0], c[2], c[3], c[1]}, {c[4], c[5], c[7], c[6]}};
  for (int a = 0; a < 3 && !faces.empty(); ++a) {
    clip_polyhedron(faces, a, 1.0, centre[a] + p.size[a]);
    if (!faces.empty()) clip_polyhedron(faces, a, -1.0, -(centre[a] - p.size[a]));
  }
  const double box = (hi - lo).prod();
  return std::clamp(polyhedron_volume(faces) / box, 0.0, 1.0);
}
}  // namespace

double coverage(const std::vector<Primitive>& prims, const Vector3d& pos, const Vector3d& lo,
                const Vector3d& hi) {
  const Vector3d llo = lo - pos, lhi = hi - pos;
  const Primitive* only = nullptr;
  int touching = 0;
  for (const Primitive& p : prims) {
    if (!box_touches(p, llo, lhi)) continue;
    if (holds_box(p, llo, lhi)) return 1.0;
    only = &p;
    ++touching;
  }
  if (touching == 0) return 0.0;
  if (touching == 1 && only->kind == PrimitiveKind::Cuboid) {
    const Vector3d a = only->lower(), b = only->upper();
    return overlap(llo.x(), lhi.x(), a.x(), b.x()) * overlap(llo.y(), lhi.y(), a.y(), b.y()) *
           overlap(llo.z(), lhi.z(), a.z(), b.z());
  }
  return sampled_share(llo, lhi, [&](const Vector3d& q) {
    for (const Primitive& p : prims)
      if (p.inside(q)) return true;
    return false;
  });
}

namespace {
// The voxels a world box [lo, hi] touches, clamped to the grid.
VoxelBox voxel_box_of(const Vector3d& lo, const Vector3d& hi, const terrain::Grid3Shape& shape) {
  VoxelBox box;
  const Eigen::Vector3i n(shape.nx, shape.ny, shape.nz);
  for (int a = 0; a < 3; ++a) {
    const double l = std::floor((lo[a] - shape.origin[a]) / shape.voxel_size);
    const double h = std::ceil((hi[a] - shape.origin[a]) / shape.voxel_size);
    box.lo[a] = static_cast<int>(std::clamp(l, 0.0, static_cast<double>(n[a])));
    box.hi[a] = static_cast<int>(std::clamp(h, 0.0, static_cast<double>(n[a])));
  }
  return box;
}
}  // namespace

VoxelBox voxel_box(const std::vector<Primitive>& prims, const Vector3d& pos,
                   const terrain::Grid3Shape& shape) {
  Vector3d lo = Vector3d::Constant(1e300), hi = Vector3d::Constant(-1e300);
  for (const Primitive& p : prims) {
    lo = lo.cwiseMin(p.lower() + pos);
    hi = hi.cwiseMax(p.upper() + pos);
  }
  return voxel_box_of(lo, hi, shape);
}

namespace {
// Hands fill(index, share) every voxel of `box` that `share_of(lo, hi)` (its
// corners in metres) covers, rows of y in parallel (each voxel from one task).
template <class ShareOf>
void fill_box(const VoxelBox& box, const terrain::Grid3Shape& shape,
              const std::function<void(std::size_t, float)>& fill, const ShareOf& share_of) {
  const double h = shape.voxel_size;
  tbb::parallel_for(box.lo.y(), box.hi.y(), [&](int y) {
    for (int x = box.lo.x(); x < box.hi.x(); ++x)
      for (int z = box.lo.z(); z < box.hi.z(); ++z) {
        const Vector3d lo = shape.origin + h * Vector3d(x, y, z);
        const double c = share_of(lo, lo + Vector3d::Constant(h));
        if (c > 0.0) fill(shape.index(x, y, z), static_cast<float>(c));
      }
  });
}
}  // namespace

void for_each_covered_voxel(const std::vector<Primitive>& prims, const Vector3d& pos,
                            const terrain::Grid3Shape& shape,
                            const std::function<void(std::size_t, float)>& fill) {
  const VoxelBox box = voxel_box(prims, pos, shape);
  if (box.empty()) return;
  fill_box(box, shape, fill,
           [&](const Vector3d& lo, const Vector3d& hi) { return coverage(prims, pos, lo, hi); });
}

void add_coverage(const std::vector<Primitive>& prims, const Vector3d& pos,
                  const terrain::Grid3Shape& shape, std::vector<float>& field) {
  for_each_covered_voxel(prims, pos, shape, [&field](std::size_t i, float c) {
    field[i] = std::min(1.0f, field[i] + c);
  });
}

namespace {
// World bounding box of the body-frame box [lo, hi] at `pose`.
void placed_bounds(const Pose& pose, const Vector3d& lo, const Vector3d& hi, Vector3d& wlo,
                   Vector3d& whi) {
  for (int c = 0; c < 8; ++c) {
    const Vector3d corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(),
                          (c & 4) ? hi.z() : lo.z());
    const Vector3d w = pose.position + pose.rotation * corner;
    wlo = wlo.cwiseMin(w);
    whi = whi.cwiseMax(w);
  }
}

bool plain(const PlacedSolid& s) { return !s.mesh && !s.pose.rotated(); }
}  // namespace

VoxelBox voxel_box(const PlacedSolid& solid, const terrain::Grid3Shape& shape) {
  if (plain(solid)) return voxel_box(*solid.primitives, solid.pose.position, shape);
  Vector3d lo = Vector3d::Constant(1e300), hi = Vector3d::Constant(-1e300);
  for (const Primitive& p : *solid.primitives)
    placed_bounds(solid.pose, p.lower(), p.upper(), lo, hi);
  if (solid.mesh) placed_bounds(solid.pose, solid.mesh->lower(), solid.mesh->upper(), lo, hi);
  return voxel_box_of(lo, hi, shape);
}

namespace {
// How a world box lies against a turned solid: 1 wholly inside, 0 wholly
// outside, -1 undecided; `only` is the one primitive that touches it (if
// just one does and no mesh does).
int classify(const PlacedSolid& solid, const Vector3d& lo, const Vector3d& hi,
             const Primitive*& only) {
  Vector3d corners[8], blo = Vector3d::Constant(1e300), bhi = Vector3d::Constant(-1e300);
  for (int c = 0; c < 8; ++c) {
    corners[c] = solid.pose.to_body(
        Vector3d((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z()));
    blo = blo.cwiseMin(corners[c]);
    bhi = bhi.cwiseMax(corners[c]);
  }
  // The mesh's solid is its cells (solid_mesh.h): exact by their box test.
  const int mesh = solid.mesh ? solid.mesh->classify(blo, bhi) : 0;
  if (mesh == 1) return 1;
  int touching = mesh != 0 ? 2 : 0;
  only = nullptr;
  const Vector3d centre = solid.pose.to_body(0.5 * (lo + hi));
  const double radius = 0.5 * (hi - lo).norm();
  for (const Primitive& p : *solid.primitives) {
    if (!box_touches(p, blo, bhi) || p.misses_ball(centre, radius)) continue;
    bool all = true;  // a convex primitive holding all eight corners holds the box
    for (const Vector3d& c : corners) all = all && p.inside(c);
    if (all) return 1;
    only = &p;
    ++touching;
  }
  if (touching == 0) return 0;
  if (touching != 1) only = nullptr;
  return -1;
}
}  // namespace

double refined_share(const PlacedSolid& solid, const Vector3d& lo, const Vector3d& hi, int depth,
                     double* undecided) {
  const Primitive* only = nullptr;
  const int c = classify(solid, lo, hi, only);
  if (c >= 0) return c;
  if (only && only->kind == PrimitiveKind::Cuboid) return cuboid_share(*only, solid.pose, lo, hi);
  if (depth == 0) {
    // Undecided at the finest level: the share at its 2 x 2 x 2 sub-box
    // centres, off by at most the box's whole volume.
    if (undecided) *undecided += 1.0;
    int in = 0;
    for (int k = 0; k < 8; ++k) {
      const Vector3d f(0.25 + 0.5 * (k & 1), 0.25 + 0.5 * ((k >> 1) & 1), 0.25 + 0.5 * (k >> 2));
      const Vector3d q = solid.pose.to_body(lo + (hi - lo).cwiseProduct(f));
      bool inside = solid.mesh && solid.mesh->inside(q);
      for (const Primitive& p : *solid.primitives)
        if (inside || (inside = p.inside(q))) break;
      in += inside;
    }
    return in / 8.0;
  }
  const Vector3d mid = 0.5 * (lo + hi);
  double sum = 0;
  for (int k = 0; k < 8; ++k) {
    const Vector3d a((k & 1) ? mid.x() : lo.x(), (k & 2) ? mid.y() : lo.y(),
                     (k & 4) ? mid.z() : lo.z());
    const Vector3d b((k & 1) ? hi.x() : mid.x(), (k & 2) ? hi.y() : mid.y(),
                     (k & 4) ? hi.z() : mid.z());
    double u = 0;
    sum += refined_share(solid, a, b, depth - 1, undecided ? &u : nullptr);
    if (undecided) *undecided += u / 8.0;
  }
  return sum / 8.0;
}

double coverage(const PlacedSolid& solid, const Vector3d& lo, const Vector3d& hi) {
  if (plain(solid)) return coverage(*solid.primitives, solid.pose.position, lo, hi);
  return refined_share(solid, lo, hi, kRefineDepth);
}

namespace {
// refined_share's answer for a voxel, decided first by its bounding ball
// alone where that suffices (issue 33's follow-up: most voxels of a turned
// body's box lie wholly inside or outside it, and classify turned all eight
// corners into the body's frame and tested each). A ball that one convex
// primitive holds, with a margin far above the rounding of the corners'
// transform, means that primitive holds all eight corners: refined_share
// gives 1. Without a mesh, a ball every primitive misses (the very centre,
// radius and test classify uses) means it gives 0. Else refined_share
// itself: the shares are its, bit for bit
// (`SoilPrimitives.BallShortcutGivesRefinedShareBitForBit`).
double voxel_share(const PlacedSolid& solid, const Vector3d& lo, const Vector3d& hi) {
  const Vector3d centre = solid.pose.to_body(0.5 * (lo + hi));
  const double radius = 0.5 * (hi - lo).norm();
  const double margin =
      1e-9 * (radius + centre.norm() + solid.pose.position.norm() + (0.5 * (lo + hi)).norm());
  bool missed = !solid.mesh;
  for (const Primitive& p : *solid.primitives) {
    if (p.holds_ball(centre, radius + margin)) return 1.0;
    missed = missed && p.misses_ball(centre, radius);
  }
  if (missed) return 0.0;
  return refined_share(solid, lo, hi, kRefineDepth);
}
}  // namespace

void for_each_covered_voxel(const PlacedSolid& solid, const terrain::Grid3Shape& shape,
                            const std::function<void(std::size_t, float)>& fill) {
  if (plain(solid))
    return for_each_covered_voxel(*solid.primitives, solid.pose.position, shape, fill);
  const VoxelBox box = voxel_box(solid, shape);
  if (box.empty()) return;
  fill_box(box, shape, fill,
           [&](const Vector3d& lo, const Vector3d& hi) { return voxel_share(solid, lo, hi); });
}

void add_coverage(const PlacedSolid& solid, const terrain::Grid3Shape& shape,
                  std::vector<float>& field) {
  for_each_covered_voxel(
      solid, shape, [&field](std::size_t i, float c) { field[i] = std::min(1.0f, field[i] + c); });
}

}  // namespace drift::soil
