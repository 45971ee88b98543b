#include "terrain/marks/multires.h"

#include <algorithm>
#include <cmath>

#include "terrain/bilinear.h"
#include "terrain/marks/displacement.h"
#include "terrain/slope_relax.h"

namespace drift::marks {

namespace {

// The fine window around the triangles, aligned to whole blocks of `level`.
CellWindow block_window(const CellTriangles& tris, int level, int margin, int grid_w, int grid_h) {
  const CellWindow w = footprint_window(tris, margin * level, grid_w, grid_h);
  if (w.empty()) return w;
  const int c0 = w.col0 / level * level, r0 = w.row0 / level * level;
  const int cw = std::min(w.col0 + w.width - c0 + level - 1, grid_w - c0) / level;
  const int ch = std::min(w.row0 + w.height - r0 + level - 1, grid_h - r0) / level;
  return {c0, r0, cw * level, ch * level};
}

struct Coarse {
  terrain::Grid<double> heights;
  MaterialField materials;
};

// Block means of the heights (volume kept); each block takes its centre cell's material.
Coarse coarsen(const terrain::Grid<double>& h, const MaterialField& m, const CellWindow& w,
               int level) {
  const int cw = w.width / level, ch = w.height / level;
  Coarse c{terrain::Grid<double>(cw, ch, 0.0), MaterialField{m.table, {}}};
  if (!m.index.empty()) c.materials.index = terrain::Grid<std::uint8_t>(cw, ch, 0);
  for (int j = 0; j < ch; ++j)
    for (int i = 0; i < cw; ++i) {
      double sum = 0.0;
      for (int y = 0; y < level; ++y)
        for (int x = 0; x < level; ++x) sum += h(w.col0 + i * level + x, w.row0 + j * level + y);
      c.heights(i, j) = sum / (level * level);
      if (!m.index.empty())
        c.materials.index(i, j) =
            m.index(w.col0 + i * level + level / 2, w.row0 + j * level + level / 2);
    }
  return c;
}

// Adds the coarse change, interpolated, to the fine cells around where it changed.
void write_back(terrain::Grid<double>& h, const terrain::Grid<double>& delta, const CellWindow& w,
                int level, CoarseResult& r, terrain::Grid<float>* disturbed) {
  int i0 = delta.width(), i1 = -1, j0 = delta.height(), j1 = -1;
  for (int j = 0; j < delta.height(); ++j)
    for (int i = 0; i < delta.width(); ++i)
      if (delta(i, j) != 0.0)
        i0 = std::min(i0, i), i1 = std::max(i1, i), j0 = std::min(j0, j), j1 = std::max(j1, j);
  if (i1 < 0) return;
  const int x0 = w.col0 + std::max(i0 - 1, 0) * level,
            x1 = w.col0 + std::min(i1 + 2, delta.width()) * level;
  const int y0 = w.row0 + std::max(j0 - 1, 0) * level,
            y1 = w.row0 + std::min(j1 + 2, delta.height()) * level;
  const double centre = 0.5 * (level - 1);  // fine offset of a block's centre
  const auto at = [&](int i, int j) { return delta(i, j); };
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const double add =
          terrain::bilinear_clamped(at, delta.width(), delta.height(),
                                    (x - w.col0 - centre) / level, (y - w.row0 - centre) / level);
      if (add == 0.0) continue;
      h(x, y) += add;
      r.changed.push_back(y * h.width() + x);
      if (disturbed) (*disturbed)(x, y) += static_cast<float>(std::abs(add));
    }
}

}  // namespace

CoarseResult deform_coarse(terrain::Grid<double>& heights, const MaterialField& materials,
                           const CellTriangles& tris, int level, double dx, double dy, int margin,
                           int erosion_passes, BottomRasteriser& rasteriser,
                           const std::optional<Eigen::Vector2d>& drag,
                           terrain::Grid<float>* disturbed, std::uint64_t seed) {
  CoarseResult r;
  const CellWindow w = block_window(tris, level, margin, heights.width(), heights.height());
  if (w.empty()) return r;
  Coarse c = coarsen(heights, materials, w, level);
  const double centre = 0.5 * (level - 1);
  CellTriangles coarse_tris(tris.size());
  for (std::size_t i = 0; i < tris.size(); ++i)
    coarse_tris[i] = {(tris[i].x() - w.col0 - centre) / level,
                      (tris[i].y() - w.row0 - centre) / level, tris[i].z()};
  BottomMap cb;
  cb.window = {0, 0, c.heights.width(), c.heights.height()};
  rasteriser.render(coarse_tris, cb);
  const terrain::Grid<double> before = c.heights;
  const DisplacementReport d =
      compress_and_displace(c.heights, cb, c.materials, drag, nullptr, dx * level, dy * level);
  r.collided = d.collided, r.displaced = d.displaced, r.compressed = d.compressed;
  r.contact_cells = static_cast<int>(d.contact.size());
  if (!d.contact.empty()) {
    terrain::Grid<double> ceiling(cb.window.width, cb.window.height);
    ceiling.values() = cb.z;
    std::vector<terrain::SlopeRule> rules;
    for (const Material& m : c.materials.table) rules.push_back(m.slope_rule());
    terrain::SlopeCells cells{rules, c.materials.index.empty() ? nullptr : &c.materials.index,
                              &ceiling, nullptr};
    std::vector<int> seeds = d.received, moved;
    seeds.insert(seeds.end(), d.contact.begin(), d.contact.end());
    terrain::relax_slopes(c.heights, seeds, cells,
                          {dx * level, dy * level, 1e-4 * std::min(dx, dy), erosion_passes, seed},
                          moved);
  }
  terrain::Grid<double> delta(c.heights.width(), c.heights.height());
  for (std::size_t i = 0; i < delta.size(); ++i)
    delta.values()[i] = c.heights.values()[i] - before.values()[i];
  write_back(heights, delta, w, level, r, disturbed);
  r.bottom.window = w;
  r.bottom.z.resize(static_cast<std::size_t>(w.width) * w.height);
  for (int y = 0; y < w.height; ++y)
    for (int x = 0; x < w.width; ++x)
      r.bottom.z[static_cast<std::size_t>(y) * w.width + x] =
          cb.z[static_cast<std::size_t>(y / level) * cb.window.width + x / level];
  return r;
}

}  // namespace drift::marks
