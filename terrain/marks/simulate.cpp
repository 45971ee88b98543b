// simulate_marks: the run over every object's keyframes (marks.h).
#include <algorithm>
#include <cmath>

#include "terrain/bilinear.h"
#include "terrain/error.h"
#include "terrain/marks/marks.h"

namespace drift::marks {

namespace {

// The ground's height under a point (bilinear between cell centres, clamped at
// the edges), for objects that follow the ground.
double ground_under(const terrain::HeightField& g, const GridFrame& f, double x, double y) {
  return terrain::bilinear_clamped(g, (x - f.x0) / f.dx, (f.y0 - y) / f.dy);
}

void validate_objects(const std::vector<MarkObject>& objects) {
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const MarkObject& o = objects[i];
    const std::string what =
        "object " + std::to_string(i + 1) + (o.name.empty() ? "" : " ('" + o.name + "')");
    if (o.mesh.triangles.empty()) throw Error(what + ": the mesh has no triangles");
    for (const auto& p : o.mesh.positions)
      if (!p.allFinite()) throw Error(what + ": the mesh has a vertex that is not finite");
    o.trajectory.validate(what);
    if (o.material) o.material->validate(what);
    if (o.resolution != 0 && o.resolution != 1 && o.resolution != 2 && o.resolution != 4)
      throw Error(what + ": resolution is " + std::to_string(o.resolution) +
                  "; use 1, 2, 4 or 0 (auto)");
  }
}

}  // namespace

Pose object_pose(const MarkObject& object, const terrain::HeightField& ground, double t) {
  Pose p = object.trajectory.at(t);
  if (object.follow_ground) {
    const GridFrame f = GridFrame::of(ground.geo());
    p.position.z() += ground_under(ground, f, p.position.x(), p.position.y());
  }
  return p;
}

Pose object_pose(const MarkObject& object, const GroundAt& ground_at, double t) {
  Pose p = object.trajectory.at(t);
  if (object.follow_ground) p.position.z() += ground_at(p.position.x(), p.position.y());
  return p;
}

terrain::Mesh posed_objects(const std::vector<MarkObject>& objects,
                            const terrain::HeightField& ground, double t) {
  terrain::Mesh out;
  // Float positions measured from the raster's north-west corner (a UTM
  // coordinate would lose its centimetres in a float).
  const auto& gt = ground.geo().geotransform;
  out.origin = {gt[0], gt[3], 0.0};
  for (const MarkObject& o : objects) {
    const Pose p = object_pose(o, ground, t);
    const Eigen::Matrix3d r = p.rotation.toRotationMatrix();
    const int base = static_cast<int>(out.positions.size());
    for (const auto& v : o.mesh.positions)
      out.positions.push_back((p.position + r * v.cast<double>() - out.origin).cast<float>());
    for (const auto& tri : o.mesh.triangles)
      out.triangles.push_back({tri[0] + base, tri[1] + base, tri[2] + base});
  }
  return out;
}

double run_end(const std::vector<MarkObject>& objects) {
  double t1 = -1e300;
  for (const MarkObject& o : objects) t1 = std::max(t1, o.trajectory.end());
  return t1;
}

MarksResult simulate_marks(const terrain::HeightField& ground,
                           const std::vector<MarkObject>& objects, MaterialField materials,
                           const MarksOptions& options, const StepFn& on_step,
                           const ProgressFn& progress) {
  return simulate_marks_on(ground, objects, std::move(materials), options, {}, on_step, progress);
}

MarksResult simulate_marks_on(const terrain::HeightField& ground,
                              const std::vector<MarkObject>& objects, MaterialField materials,
                              const MarksOptions& options, const GroundAt& ground_at,
                              const StepFn& on_step, const ProgressFn& progress) {
  options.validate();
  validate_objects(objects);
  if (objects.empty()) throw Error("marks: no objects to move");
  MarksSimulation sim(ground, std::move(materials), options);
  std::vector<ObjectShape> shapes;
  shapes.reserve(objects.size());
  for (const MarkObject& o : objects) shapes.push_back(ObjectShape::of(o.mesh));
  double t0 = 1e300, t1 = -1e300;
  for (const MarkObject& o : objects)
    t0 = std::min(t0, o.trajectory.start()), t1 = std::max(t1, o.trajectory.end());
  const double span = (t1 - t0) / options.step;
  if (span > 1e7)
    throw Error("marks: the keyframes span " + std::to_string(span) + " steps; raise 'step'");
  const int steps = static_cast<int>(std::ceil(span - 1e-9));
  auto pose_of = [&](const MarkObject& o, double t) {
    return ground_at ? object_pose(o, ground_at, t) : object_pose(o, ground, t);
  };
  MarksResult result;
  for (const MarkObject& o : objects) result.report.objects.push_back({o.name});
  if (progress && !progress(0.0, "marks")) throw Cancelled();
  for (int k = 0; k <= steps; ++k) {
    const double t = std::min(t0 + k * options.step, t1), t_prev = t0 + (k - 1) * options.step;
    bool contact = false;
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const MarkObject& o = objects[i];
      if (!o.trajectory.active_at(t)) continue;
      const bool first = k == 0 || !o.trajectory.active_at(t_prev);
      const Pose to = pose_of(o, t), from = first ? to : pose_of(o, t_prev);
      const StepReport r = sim.move(shapes[i], o, from, to, first);
      result.report.collided += r.collided, result.report.displaced += r.displaced;
      result.report.compressed += r.compressed;
      ObjectReport& each = result.report.objects[i];
      ++each.steps;
      const bool touched = r.touched() || r.contact_cells > 0;
      if (touched) ++each.contact_steps, contact = true;
      if (options.window)
        result.report.object_steps.push_back(
            {k, static_cast<int>(i), r.collided, r.displaced, r.compressed, touched});
      if (r.clearance < each.clearance)
        each.clearance = r.clearance, each.bottom = r.bottom, each.ground = r.ground;
    }
    if (contact) ++result.report.contact_steps;
    sim.end_step();
    if (on_step && !on_step(k, sim)) throw Cancelled();
    if (progress && !progress(static_cast<double>(k + 1) / (steps + 1), "marks")) throw Cancelled();
  }
  result.report.steps = steps + 1;
  result.heights = sim.heights_as_float();
  result.disturbed = sim.disturbed();
  return result;
}

}  // namespace drift::marks
