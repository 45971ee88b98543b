// Marks block by block (marks_blocks.h).
#include "terrain/marks/marks_blocks.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "terrain/bilinear.h"
#include "terrain/error.h"
#include "terrain/raster_blocks.h"
#include "terrain/raster_io.h"

namespace drift::marks {

namespace {

constexpr int kBlock = 1024;

// Cells [x0, x1) x [y0, y1) of the raster.
struct Rect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool meets(const Rect& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  bool holds(const Rect& o) const { return x0 <= o.x0 && y0 <= o.y0 && o.x1 <= x1 && o.y1 <= y1; }
  Rect grown(int by) const { return {x0 - by, y0 - by, x1 + by, y1 + by}; }
  Rect clipped(int w, int h) const {
    return {std::max(x0, 0), std::max(y0, 0), std::min(x1, w), std::min(y1, h)};
  }
  void add(const Rect& o) {
    x0 = std::min(x0, o.x0), y0 = std::min(y0, o.y0);
    x1 = std::max(x1, o.x1), y1 = std::max(y1, o.y1);
  }
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

int round_up4(int n) { return (n + 3) / 4 * 4; }

// Where each object can touch the ground in each of its steps, in raster
// cells: its bounding sphere about its origin at the step and the step before
// (a swept drag covers both), grown by the rim's margin at the coarsest level
// and two cells; the steps of simulate_marks. Counts each object's steps.
struct Footprint {
  Rect box;
  int object = 0, step = 0;
};
std::vector<Footprint> footprints(const std::vector<MarkObject>& objects, const MarksOptions& o,
                                  const GridFrame& f, MarksReport& report) {
  double t0 = 1e300, t1 = -1e300;
  for (const MarkObject& ob : objects)
    t0 = std::min(t0, ob.trajectory.start()), t1 = std::max(t1, ob.trajectory.end());
  const int steps = static_cast<int>(std::ceil((t1 - t0) / o.step - 1e-9));
  std::vector<Footprint> out;
  report.steps = steps + 1;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const MarkObject& ob = objects[i];
    const ObjectShape shape = ObjectShape::of(ob.mesh);
    const double reach = 4.0 * (o.margin + 2);
    const double rx = shape.radius / f.dx + reach, ry = shape.radius / f.dy + reach;
    bool had = false;
    Rect last;
    for (int k = 0; k <= steps; ++k) {
      const double t = std::min(t0 + k * o.step, t1);
      if (!ob.trajectory.active_at(t)) {
        had = false;
        continue;
      }
      ++report.objects[i].steps;
      const Eigen::Vector3d p = ob.trajectory.at(t).position;
      const double c = (p.x() - f.x0) / f.dx, r = (f.y0 - p.y()) / f.dy;
      Rect box{static_cast<int>(std::floor(std::max(c - rx, -1e9))),
               static_cast<int>(std::floor(std::max(r - ry, -1e9))),
               static_cast<int>(std::ceil(std::min(c + rx, 1e9))) + 1,
               static_cast<int>(std::ceil(std::min(r + ry, 1e9))) + 1};
      Rect step = box;
      if (had) step.add(last);
      out.push_back({step, static_cast<int>(i), k});
      last = box, had = true;
    }
  }
  return out;
}

// A cell of `result` within `band` cells of the window's edge, where that edge
// is not the raster's, that the run changed or disturbed.
bool reaches_edge(const Rect& win, int width, int height, int band,
                  const terrain::HeightField& before, const MarksResult& result) {
  const int w = win.width(), h = win.height();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool near = (win.x0 > 0 && x < band) || (win.y0 > 0 && y < band) ||
                        (win.x1 < width && x >= w - band) || (win.y1 < height && y >= h - band);
      if (!near) continue;
      if (result.heights(x, y) != before(x, y) || result.disturbed(x, y) != 0.0f) return true;
    }
  return false;
}

// The ground's materials on a window: one material, or per region from a
// raster read through GDAL a window at a time, as the ground is, giving each
// cell the one-pass run's material (the same table, the same indices).
class WindowMaterials {
 public:
  WindowMaterials(const MarksBlockFiles& f, const Material& ground, int width, int height)
      : ground_(ground), snow_min_(f.snow_min), snow_(f.snow) {
    if (!f.materials.empty() && !f.snow_depth.empty())
      throw Error("marks: give --materials or --snow-depth, not both");
    auto open = [&](const std::filesystem::path& p, const char* what, const char* fix) {
      auto r = std::make_unique<terrain::RasterBlockReader>(p);
      if (r->width() != width || r->height() != height)
        throw Error(std::string(what) + " '" + p.string() + "' is " + std::to_string(r->width()) +
                    " x " + std::to_string(r->height()) + " cells but the ground is " +
                    std::to_string(width) + " x " + std::to_string(height) + "; " + fix);
      return r;
    };
    if (!f.materials.empty()) {
      materials_ = open(f.materials, "material raster", "give one value a cell of the ground");
      what_ = "material raster '" + f.materials.string() + "'";
      for (const char* name : {"sand", "mud", "snow"}) table_.push_back(*material_preset(name));
    }
    if (!f.snow_depth.empty())
      snow_depth_ =
          open(f.snow_depth, "snow depth", "give the depth drift snow fall made on this ground");
  }
  MaterialField of(const Rect& win) const {
    if (!materials_ && !snow_depth_) return MaterialField{{ground_}, {}};
    const terrain::RasterBlockReader& r = materials_ ? *materials_ : *snow_depth_;
    // Indices are not heights: read them as they are (materials_from_raster
    // names a cell that holds no index); depths are read as heights.
    const std::vector<float> v =
        r.read(win.x0, win.y0, win.width(), win.height(), /*heights=*/!materials_);
    terrain::Grid<float> g(win.width(), win.height(), 0.0f);
    std::copy(v.begin(), v.end(), g.values().begin());
    if (materials_) return materials_from_raster(g, table_, what_, win.x0, win.y0);
    return materials_from_snow_depth(g, snow_min_, ground_, snow_);
  }

 private:
  Material ground_;
  double snow_min_;
  Material snow_;
  std::unique_ptr<terrain::RasterBlockReader> materials_, snow_depth_;
  std::vector<Material> table_;
  std::string what_;
};

}  // namespace

MarksBlockReport marks_to_files(const MarksBlockFiles& files,
                                const std::vector<MarkObject>& objects, const Material& material,
                                const MarksOptions& options, const ProgressFn& progress) {
  options.validate();
  if (objects.empty()) throw Error("marks: no objects to move");
  if (files.halo < 0)
    throw Error("marks: --halo is " + std::to_string(files.halo) + "; give 0 or more cells");
  terrain::RasterBlockReader reader(files.ground);
  const int width = reader.width(), height = reader.height();
  const terrain::GeoReference& geo = reader.geo();
  const GridFrame frame = GridFrame::of(geo);
  MarksBlockReport out;
  out.block = round_up4(terrain::block_cells(files.block, kBlock));
  out.halo = round_up4(files.halo);
  for (const MarkObject& ob : objects) out.report.objects.push_back({ob.name});
  const std::vector<Footprint> boxes = footprints(objects, options, frame, out.report);
  // Each object's step once (slot step x objects + object), from the first
  // accepted window that holds its footprint whole: a window runs every
  // object along its whole track, so the same step comes from several.
  const std::size_t n_objects = objects.size();
  std::vector<ObjectStep> taken(static_cast<std::size_t>(out.report.steps) * n_objects);
  std::vector<char> have(taken.size(), 0);
  std::vector<int> box_of(taken.size(), -1);
  for (std::size_t b = 0; b < boxes.size(); ++b)
    box_of[static_cast<std::size_t>(boxes[b].step) * n_objects +
           static_cast<std::size_t>(boxes[b].object)] = static_cast<int>(b);
  const WindowMaterials window_materials(files, material, width, height);

  // Objects that follow the ground stand on the raster's heights (simulate's
  // ground_under on the whole raster: the same cell, fractions and blend).
  const GroundAt ground_at = [&](double x, double y) {
    const double u = (x - frame.x0) / frame.dx, v = (frame.y0 - y) / frame.dy;
    const terrain::BilinearCell<double> c = terrain::clamped_cell(u, v, width, height);
    const std::vector<float> q = reader.read(c.x0, c.y0, c.x1 - c.x0 + 1, c.y1 - c.y0 + 1);
    const int qw = c.x1 - c.x0 + 1;
    auto at = [&](int cx, int cy) {
      return static_cast<double>(q[static_cast<std::size_t>(cy - c.y0) * qw + (cx - c.x0)]);
    };
    return static_cast<double>(static_cast<float>(terrain::bilinear_blend<double, double>(
        at(c.x0, c.y0), at(c.x1, c.y0), at(c.x0, c.y1), at(c.x1, c.y1), c.tx, c.ty)));
  };

  terrain::RasterBlockWriter heights_out(files.output, width, height, geo,
                                         {"ground height with marks (m)", "m"});
  std::unique_ptr<terrain::RasterBlockWriter> disturbed_out;
  if (!files.disturbed.empty())
    disturbed_out = std::make_unique<terrain::RasterBlockWriter>(
        files.disturbed, width, height, geo,
        terrain::WriteOptions{"ground disturbed by marks (m compressed, displaced or slid)", "m"});

  const int band = 2 + options.margin;
  const int bx_count = (width + out.block - 1) / out.block;
  const int by_count = (height + out.block - 1) / out.block;
  out.blocks = bx_count * by_count;
  std::vector<float> cells;
  for (int j = 0; j < by_count; ++j)
    for (int i = 0; i < bx_count; ++i) {
      const Rect block =
          Rect{i * out.block, j * out.block, (i + 1) * out.block, (j + 1) * out.block}.clipped(
              width, height);
      const int bw = block.width(), bh = block.height();
      bool near = false;
      for (const Footprint& b : boxes) near = near || b.box.meets(block.grown(out.halo));
      if (!near) {  // no object comes within the halo: the ground as it was
        cells = reader.read(block.x0, block.y0, bw, bh);
        heights_out.write(block.x0, block.y0, bw, bh, cells.data());
        if (disturbed_out) {
          cells.assign(cells.size(), 0.0f);
          disturbed_out->write(block.x0, block.y0, bw, bh, cells.data());
        }
      } else {
        ++out.simulated;
        for (int halo = out.halo;; halo = std::max(2 * halo, 4)) {
          // The block and its halo, grown to hold whole every footprint that
          // comes into it, from a multiple of 4 cells (the coarse levels').
          const Rect first = block.grown(halo);
          Rect win = first;
          for (const Footprint& b : boxes)
            if (b.box.meets(first)) win.add(b.box);
          win.x0 = win.x0 / 4 * 4, win.y0 = win.y0 / 4 * 4;
          win = win.clipped(width, height);
          terrain::HeightField ground(win.width(), win.height(), 0.0f, geo);
          cells = reader.read(win.x0, win.y0, win.width(), win.height());
          std::copy(cells.begin(), cells.end(), ground.values().begin());
          auto& gt = ground.geo().geotransform;
          gt[0] += win.x0 * gt[1], gt[3] += win.y0 * gt[5];
          MarksOptions o = options;
          o.track_disturbed = true;  // the edge check reads it
          o.window = MarksOptions::Window{win.x0, win.y0, width, frame.x0, frame.y0};
          const MarksResult r =
              simulate_marks_on(ground, objects, window_materials.of(win), o, ground_at);
          const bool whole = win.x0 == 0 && win.y0 == 0 && win.x1 == width && win.y1 == height;
          if (!whole && reaches_edge(win, width, height, band, ground, r)) {
            ++out.widened;
            continue;
          }
          out.largest_halo = std::max(out.largest_halo, halo);
          for (std::size_t k = 0; k < objects.size(); ++k) {
            const ObjectReport& a = r.report.objects[k];
            ObjectReport& b = out.report.objects[k];
            if (a.clearance < b.clearance)
              b.clearance = a.clearance, b.bottom = a.bottom, b.ground = a.ground;
          }
          for (const ObjectStep& e : r.report.object_steps) {
            const std::size_t slot =
                static_cast<std::size_t>(e.step) * n_objects + static_cast<std::size_t>(e.object);
            if (have[slot] || box_of[slot] < 0) continue;
            const Rect box =
                boxes[static_cast<std::size_t>(box_of[slot])].box.clipped(width, height);
            if (box.width() > 0 && box.height() > 0 && !win.holds(box)) continue;
            taken[slot] = e, have[slot] = 1;
          }
          auto put = [&](terrain::RasterBlockWriter& writer, const terrain::Grid<float>& g) {
            cells.resize(static_cast<std::size_t>(bw) * bh);
            for (int y = 0; y < bh; ++y)
              for (int x = 0; x < bw; ++x)
                cells[static_cast<std::size_t>(y) * bw + x] =
                    g(block.x0 - win.x0 + x, block.y0 - win.y0 + y);
            writer.write(block.x0, block.y0, bw, bh, cells.data());
          };
          put(heights_out, r.heights);
          if (disturbed_out) put(*disturbed_out, r.disturbed);
          break;
        }
      }
      if (!progress(static_cast<double>(j * bx_count + i + 1) / out.blocks, "marks"))
        throw Cancelled();
    }
  // The one-pass run's sums, in its order (step by step, object by object).
  for (int k = 0; k < out.report.steps; ++k) {
    bool contact = false;
    for (std::size_t i = 0; i < n_objects; ++i) {
      const std::size_t slot = static_cast<std::size_t>(k) * n_objects + i;
      if (!have[slot]) continue;
      const ObjectStep& e = taken[slot];
      out.report.collided += e.collided, out.report.displaced += e.displaced;
      out.report.compressed += e.compressed;
      if (e.contact) ++out.report.objects[i].contact_steps, contact = true;
    }
    if (contact) ++out.report.contact_steps;
  }
  heights_out.finish();
  if (disturbed_out) disturbed_out->finish();
  return out;
}

}  // namespace drift::marks
