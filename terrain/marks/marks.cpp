#include "terrain/marks/marks.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "terrain/angles.h"
#include "terrain/error.h"
#include "terrain/hash.h"
#include "terrain/marks/displacement.h"
#include "terrain/marks/marks_parameters.h"
#include "terrain/marks/multires.h"
#include "terrain/memory.h"
#include "terrain/slope_relax.h"

namespace drift::marks {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Paper 000, 3.4: an object is dragged when it moves sideways (more than a
// twentieth of a cell) rather than down (motion at most 45 degrees below level).
std::optional<Eigen::Vector2d> drag_direction(const Eigen::Vector3d& d, const GridFrame& f) {
  const Eigen::Vector2d cells(d.x() / f.dx, -d.y() / f.dy);
  const double level = std::hypot(d.x(), d.y());
  if (cells.norm() <= 0.05 || d.z() < -level) return std::nullopt;
  return cells;
}

// How the object's lowest point moves from pose a to pose b: the motion of
// the object where it meets the ground. A sliding object drags the ground
// with it; a rolling wheel's lowest point barely moves, so it presses.
Eigen::Vector3d contact_motion(const ObjectShape& shape, const Pose& a, const Pose& b) {
  const Eigen::Matrix3d ra = a.rotation.toRotationMatrix(), rb = b.rotation.toRotationMatrix();
  std::size_t lowest = 0;
  double z = kInf;
  for (std::size_t i = 0; i < shape.mesh.positions.size(); ++i) {
    const double zi = (rb * shape.mesh.positions[i].cast<double>()).z();
    if (zi < z) z = zi, lowest = i;
  }
  const Eigen::Vector3d p = shape.mesh.positions[lowest].cast<double>();
  return (b.position + rb * p) - (a.position + ra * p);
}

// How near an object comes to the ground: its lowest gap (m) over the cells
// beneath it, with its bottom and the ground's height there.
struct Clearance {
  double gap = kInf, bottom = 0.0, ground = 0.0;
};

}  // namespace

void MarksOptions::validate() const {
  for (const MarksParameter& p : marks_parameters()) p.require(*this);
  if (camera && (!camera->position.allFinite() || !(camera->fov_deg > 0 && camera->fov_deg < 180) ||
                 camera->width_px < 1))
    throw Error(
        "marks: the camera needs a finite position, a field of view in (0, 180) degrees "
        "and a width of at least 1 pixel");
}

struct MarksSimulation::Impl {
  MarksSimulation& sim;
  std::unique_ptr<BottomRasteriser> rasteriser;
  terrain::Grid<double> ceiling;  // the objects' bottoms during erosion, +inf elsewhere
  terrain::Grid<int> expiry;      // step until which a cell is remembered (3.5)
  std::vector<int> remembered;    // the cells with expiry >= the current step
  std::vector<BottomMap> last;    // each object's last bottom in this step
  terrain::SlopeRelaxWorkspace workspace;

  explicit Impl(MarksSimulation& s) : sim(s) {}

  void remember(const std::vector<int>& cells) {
    for (int c : cells) {
      int& e = expiry.values()[static_cast<std::size_t>(c)];
      if (e < sim.step_) remembered.push_back(c);
      e = sim.step_ + sim.options_.memory_steps;
    }
  }
  void set_ceiling(const BottomMap& b, bool on) {
    const CellWindow& w = b.window;
    for (int r = 0; r < w.height; ++r)
      for (int c = 0; c < w.width; ++c) {
        double& v = ceiling(w.col0 + c, w.row0 + r);
        const double z = b.z[static_cast<std::size_t>(r) * w.width + c];
        v = on ? std::min(v, z) : kInf;
      }
  }
  // The seed of the erosion's roughness: the run's, so that a cell keeps its
  // own angle from step to step (terrain/slope_relax.h, SlopeRule::rough).
  std::uint64_t erosion_seed() const { return terrain::mix64(sim.options_.seed); }
  void erode(const std::vector<int>& seeds) {
    std::vector<terrain::SlopeRule> rules;
    for (const Material& m : sim.materials_.table) rules.push_back(m.slope_rule());
    terrain::SlopeCells cells{rules, sim.materials_.index.empty() ? nullptr : &sim.materials_.index,
                              &ceiling, nullptr};
    terrain::SlopeRelaxOptions o{sim.frame_.dx, sim.frame_.dy,
                                 1e-4 * std::min(sim.frame_.dx, sim.frame_.dy),
                                 sim.options_.erosion_passes, erosion_seed()};
    // A cell that moves no more than a thousandth of a cell in a pass (10
    // micrometres at 1 cm cells, far below what a render shows) stops keeping
    // its neighbours active: the levees' slow tail drops out while the bow
    // wave goes on (docs/marks.md, Performance: 1.2-1.4x a step, marks within
    // 1.2 mm of relaxing every mover; 3e-3 of a cell left a long-held print's
    // walls steeper than theta, MarksMemory).
    o.settle = 1e-3 * std::min(sim.frame_.dx, sim.frame_.dy);
    if (sim.options_.window) {  // a block's window draws as the whole raster does
      o.index_width = sim.options_.window->raster_width;
      o.index_x0 = sim.options_.window->col0, o.index_y0 = sim.options_.window->row0;
    }
    std::vector<int> moved;
    terrain::relax_slopes(sim.heights_, seeds, cells, o, moved,
                          sim.options_.track_disturbed ? &sim.disturbed_ : nullptr, &workspace);
    remember(moved);
  }
  // Issue 32: an object's material is recorded per cell it disturbs (its
  // contact and the cells its displaced material reaches), never over its
  // window, so it does not leak onto ground it never touched.
  void claim_material(const std::vector<int>& cells, const MarkObject& object) {
    if (!object.material || cells.empty()) return;
    MaterialField& m = sim.materials_;
    const std::uint8_t id = m.add(*object.material);
    if (m.index.empty())
      m.index = terrain::Grid<std::uint8_t>(sim.heights_.width(), sim.heights_.height(), 0);
    for (int c : cells) m.index.values()[static_cast<std::size_t>(c)] = id;
  }
  // The cells where the bottom is below the ground (the contact to come).
  std::vector<int> below(const BottomMap& b) const {
    std::vector<int> out;
    const CellWindow& w = b.window;
    for (int r = 0; r < w.height; ++r)
      for (int c = 0; c < w.width; ++c)
        if (b.z[static_cast<std::size_t>(r) * w.width + c] < sim.heights_(w.col0 + c, w.row0 + r))
          out.push_back((w.row0 + r) * sim.heights_.width() + w.col0 + c);
    return out;
  }
  // Paper 000, 3.5: the cells the object holds (its bottom at or below the
  // ground) and their neighbours (the tops of the walls) stay remembered while
  // it holds them, so the memory counts from the release and a print held for
  // any time slumps once the object has left. Returns the object's lowest
  // clearance above the ground (m; <= 0: touching) for the run's report.
  Clearance hold(const BottomMap& b) {
    Clearance out;
    const CellWindow& w = b.window;
    const int gw = sim.heights_.width(), gh = sim.heights_.height();
    std::vector<int> held;
    for (int r = 0; r < w.height; ++r)
      for (int c = 0; c < w.width; ++c) {
        const double z = b.z[static_cast<std::size_t>(r) * w.width + c];
        if (!std::isfinite(z)) continue;
        const int col = w.col0 + c, row = w.row0 + r;
        const double g = sim.heights_(col, row), gap = z - g;
        if (gap < out.gap) out = {gap, z, g};
        if (gap > 1e-9 * std::max(1.0, std::abs(g))) continue;
        for (int y = std::max(row - 1, 0); y <= std::min(row + 1, gh - 1); ++y)
          for (int x = std::max(col - 1, 0); x <= std::min(col + 1, gw - 1); ++x)
            held.push_back(y * gw + x);
      }
    remember(held);
    return out;
  }
  // The heave's band (fine cells): heave x the footing's width, at most the
  // diameter of a disc of the footprint's area (displacement.cpp), plus a
  // cell; 0 without heave.
  int heave_band(const CellTriangles& tris) const {
    double heave = 0.0;
    for (const Material& m : sim.materials_.table) heave = std::max(heave, m.heave);
    if (!(heave > 0.0)) return 0;
    const CellWindow f = footprint_window(tris, 0, sim.heights_.width(), sim.heights_.height());
    const double diameter =
        2.0 * std::sqrt(static_cast<double>(f.width) * f.height / std::numbers::pi);
    return static_cast<int>(std::ceil(kHeaveReach * heave * diameter)) + 1;
  }
  // The window's margin (cells): the options', widened by the heave's band so
  // that the heave is not cut short.
  int margin(const CellTriangles& tris) const { return sim.options_.margin + heave_band(tris); }
  // The same in blocks of `level` cells (multi-resolution, 3.6): the options'
  // margin in blocks, as the paper's, and the heave's band, whose width is the
  // footing's whatever the level, in blocks too.
  int coarse_margin(const CellTriangles& tris, int level) const {
    return sim.options_.margin + (heave_band(tris) + level - 1) / level;
  }
  // Paper 000, 3.3-3.5 on the full-resolution field: collision, displacement, erosion.
  BottomMap deform(const CellTriangles& tris, const MarkObject& object,
                   const std::optional<Eigen::Vector2d>& drag, bool erode_now, StepReport& report) {
    BottomMap bottom;
    bottom.window =
        footprint_window(tris, margin(tris), sim.heights_.width(), sim.heights_.height());
    if (bottom.window.empty()) return bottom;
    rasteriser->render(tris, bottom);
    if (object.material) claim_material(below(bottom), object);
    const DisplacementReport d = compress_and_displace(
        sim.heights_, bottom, sim.materials_, drag,
        sim.options_.track_disturbed ? &sim.disturbed_ : nullptr, sim.frame_.dx, sim.frame_.dy);
    claim_material(d.received, object);
    const double area = sim.frame_.dx * sim.frame_.dy;
    report.collided += d.collided * area, report.displaced += d.displaced * area;
    report.compressed += d.compressed * area;
    report.contact_cells += static_cast<int>(d.contact.size());
    if (d.contact.empty()) return bottom;
    std::vector<int> seeds = d.received;
    seeds.insert(seeds.end(), d.contact.begin(), d.contact.end());
    // Remember the contact and its rim even where the object holds them now:
    // they slide once it has gone (3.5).
    remember(seeds);
    // The last sub-step's erosion is the step's: end_step relaxes every
    // remembered cell, these among them, under the objects' last bottoms, so
    // eroding here too would relax the same cells twice (paper 000, 3.5:
    // erosion once a step, where needed).
    if (!erode_now) return bottom;
    set_ceiling(bottom, true);
    erode(seeds);
    set_ceiling(bottom, false);
    return bottom;
  }
};

MarksSimulation::MarksSimulation(const terrain::HeightField& ground, MaterialField materials,
                                 const MarksOptions& options)
    : materials_(std::move(materials)), frame_(GridFrame::of(ground.geo())), options_(options) {
  options_.validate();
  if (options_.window) {  // a window of a larger raster: that raster's cells
    frame_.x0 = options_.window->x0, frame_.y0 = options_.window->y0;
    frame_.col0 = options_.window->col0, frame_.row0 = options_.window->row0;
  }
  const std::uint64_t cells = static_cast<std::uint64_t>(ground.width()) * ground.height();
  // Heights, ceiling (double), disturbance, expiry (4 bytes), material (1), the
  // float copy written out (4), and the erosion's workspace (terrain/slope_relax:
  // a taker's share, 8 bytes; a giver's slot and a list stamp, 4 each; 3 bytes
  // of flags).
  require_memory(cells * (8 + 8 + 4 + 4 + 1) + cells * 4 + cells * (8 + 4 + 4 + 3),
                 "marks state for a " + std::to_string(ground.width()) + " x " +
                     std::to_string(ground.height()) + " ground",
                 "crop the ground (drift import --crop) or coarsen it (drift import --resample)");
  if (!materials_.index.empty() &&
      (materials_.index.width() != ground.width() || materials_.index.height() != ground.height()))
    throw Error("marks: the material raster is " + std::to_string(materials_.index.width()) +
                " x " + std::to_string(materials_.index.height()) + " but the ground is " +
                std::to_string(ground.width()) + " x " + std::to_string(ground.height()));
  for (const Material& m : materials_.table) m.validate("marks");
  heights_ = terrain::Grid<double>(ground.width(), ground.height(), 0.0, ground.geo());
  for (std::size_t i = 0; i < ground.size(); ++i) {
    const float v = ground.values()[i];
    if (!std::isfinite(v))
      throw Error(
          "marks: the ground has a cell that is not a finite number (nodata); fill it first (drift "
          "import)");
    heights_.values()[i] = v;
  }
  if (options_.track_disturbed)
    disturbed_ = terrain::Grid<float>(ground.width(), ground.height(), 0.0f, ground.geo());
  impl_ = std::make_unique<Impl>(*this);
  impl_->rasteriser = make_bottom_rasteriser(options_.renderer);
  impl_->ceiling = terrain::Grid<double>(ground.width(), ground.height(), kInf);
  impl_->expiry = terrain::Grid<int>(ground.width(), ground.height(), -1);
}

MarksSimulation::~MarksSimulation() = default;

int MarksSimulation::resolution_for(const MarkObject& object, const Eigen::Vector3d& where) const {
  if (object.resolution > 0) return object.resolution;
  if (!options_.camera) return 1;
  // Paper 000, 3.6 A: the projected size of a cell against a pixel.
  const double distance = (options_.camera->position - where).norm();
  const double focal_px =
      0.5 * options_.camera->width_px / std::tan(terrain::radians(0.5 * options_.camera->fov_deg));
  const double cell_px = std::min(frame_.dx, frame_.dy) * focal_px / std::max(distance, 1e-9);
  return cell_px <= 0.25 ? 4 : cell_px <= 0.5 ? 2 : 1;
}

StepReport MarksSimulation::move(const ObjectShape& shape, const MarkObject& object,
                                 const Pose& from, const Pose& to, bool first) {
  StepReport report;
  const Eigen::Vector3d d = to.position - from.position;
  const double cells_moved = std::hypot(d.x() / frame_.dx, d.y() / frame_.dy);
  const double turned = from.rotation.angularDistance(to.rotation) * shape.radius /
                        std::min(frame_.dx, frame_.dy);  // cells a vertex moves by rotation
  int n = 1;
  if (!first) {
    const double per = object.motion == Motion::SubSteps ? std::max(cells_moved, turned) : turned;
    if (object.motion != Motion::Place)
      n = std::clamp(static_cast<int>(std::ceil(per - 1e-9)), 1, 10000);
  }
  const int level = resolution_for(object, to.position);
  BottomMap last;
  for (int i = 1; i <= n; ++i) {
    const double s0 = static_cast<double>(i - 1) / n, s1 = static_cast<double>(i) / n;
    const Pose a{from.position + s0 * d, from.rotation.slerp(s0, to.rotation)};
    const Pose b{from.position + s1 * d, from.rotation.slerp(s1, to.rotation)};
    const bool sweep = !first && object.motion == Motion::Sweep;
    const CellTriangles tris =
        sweep ? swept_triangles(shape, a.position, b, frame_) : posed_triangles(shape, b, frame_);
    const auto drag = first ? std::nullopt : drag_direction(contact_motion(shape, a, b), frame_);
    if (level == 1) {
      last = impl_->deform(tris, object, drag, i < n, report);
    } else {
      if (object.material) {  // the fine cells the object will press into
        BottomMap fine;
        fine.window = footprint_window(tris, 0, heights_.width(), heights_.height());
        impl_->rasteriser->render(tris, fine);
        impl_->claim_material(impl_->below(fine), object);
      }
      CoarseResult c = deform_coarse(
          heights_, materials_, tris, level, frame_.dx, frame_.dy,
          impl_->coarse_margin(tris, level), options_.erosion_passes, *impl_->rasteriser, drag,
          options_.track_disturbed ? &disturbed_ : nullptr, impl_->erosion_seed());
      const double area = frame_.dx * frame_.dy * level * level;
      report.collided += c.collided * area, report.displaced += c.displaced * area;
      report.compressed += c.compressed * area;
      report.contact_cells += c.contact_cells;
      impl_->remember(c.changed);
      last = std::move(c.bottom);
    }
    ++report.substeps;
  }
  if (!last.window.empty()) {
    const Clearance c = impl_->hold(last);
    report.clearance = c.gap, report.bottom = c.bottom, report.ground = c.ground;
    impl_->last.push_back(std::move(last));
  }
  return report;
}

void MarksSimulation::end_step() {
  for (const BottomMap& b : impl_->last) impl_->set_ceiling(b, true);
  std::vector<int> active;
  for (int c : impl_->remembered)
    if (impl_->expiry.values()[static_cast<std::size_t>(c)] >= step_) active.push_back(c);
  impl_->remembered = active;
  if (!active.empty()) impl_->erode(active);
  for (const BottomMap& b : impl_->last) impl_->set_ceiling(b, false);
  impl_->last.clear();
  ++step_;
}

terrain::HeightField MarksSimulation::heights_as_float() const {
  terrain::HeightField out(heights_.width(), heights_.height(), 0.0f, heights_.geo());
  for (std::size_t i = 0; i < out.size(); ++i)
    out.values()[i] = static_cast<float>(heights_.values()[i]);
  return out;
}

}  // namespace drift::marks
