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
std::vector<Rect> footprints(const std::vector<MarkObject>& objects, const MarksOptions& o,
                             const GridFrame& f, MarksReport& report) {
  double t0 = 1e300, t1 = -1e300;
  for (const MarkObject& ob : objects)
    t0 = std::min(t0, ob.trajectory.start()), t1 = std::max(t1, ob.trajectory.end());
  const int steps = static_cast<int>(std::ceil((t1 - t0) / o.step - 1e-9));
  std::vector<Rect> out;
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
      out.push_back(step);
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
  const std::vector<Rect> boxes = footprints(objects, options, frame, out.report);

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
      for (const Rect& b : boxes) near = near || b.meets(block.grown(out.halo));
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
          for (const Rect& b : boxes)
            if (b.meets(first)) win.add(b);
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
              simulate_marks_on(ground, objects, MaterialField{{material}, {}}, o, ground_at);
          const bool whole = win.x0 == 0 && win.y0 == 0 && win.x1 == width && win.y1 == height;
          if (!whole && reaches_edge(win, width, height, band, ground, r)) {
            ++out.widened;
            continue;
          }
          out.largest_halo = std::max(out.largest_halo, halo);
          for (std::size_t k = 0; k < objects.size(); ++k) {
            const ObjectReport& a = r.report.objects[k];
            ObjectReport& b = out.report.objects[k];
            b.contact_steps = std::max(b.contact_steps, a.contact_steps);
            if (a.clearance < b.clearance)
              b.clearance = a.clearance, b.bottom = a.bottom, b.ground = a.ground;
          }
          out.report.contact_steps = std::max(out.report.contact_steps, r.report.contact_steps);
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
  heights_out.finish();
  if (disturbed_out) disturbed_out->finish();
  return out;
}

}  // namespace drift::marks
