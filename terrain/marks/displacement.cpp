#include "terrain/marks/displacement.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "terrain/marks/distance_transform.h"
#include "terrain/neighbours.h"

namespace drift::marks {

namespace {

using terrain::kNeighbours8;

// The window's cells with their state for one contact.
struct Patch {
  CellWindow w;
  int grid_w = 0;
  std::array<double, 8> length{};  // m from a cell's centre to neighbour k's
  std::vector<char> contact;
  std::vector<double> pending;  // displaced material waiting to move (m)
  std::vector<double> outer;    // free: Euclidean distance from the contact (m); contact: 0

  int global(int li) const { return (w.row0 + li / w.width) * grid_w + w.col0 + li % w.width; }
  int neighbour(int li, int k) const {  // local index, or -1 outside the window
    const int x = li % w.width + kNeighbours8[k].dx, y = li / w.width + kNeighbours8[k].dy;
    return (x < 0 || y < 0 || x >= w.width || y >= w.height) ? -1 : y * w.width + x;
  }
};

// Paper 000, 3.4: h' = g - b, alpha h' displaced, the rest compressed.
void collide(terrain::Grid<double>& h, const BottomMap& bottom, const MaterialField& materials,
             Patch& p, DisplacementReport& r, terrain::Grid<float>* disturbed) {
  const std::size_t n = bottom.z.size();
  p.contact.assign(n, 0);
  p.pending.assign(n, 0.0);
  for (std::size_t li = 0; li < n; ++li) {
    const int g = p.global(static_cast<int>(li));
    double& height = h.values()[static_cast<std::size_t>(g)];
    if (!(bottom.z[li] < height)) continue;
    const double lost = height - bottom.z[li];
    const double alpha = materials.at(g).alpha;
    p.contact[li] = 1;
    p.pending[li] = alpha * lost;
    height = bottom.z[li];
    r.collided += lost;
    r.displaced += alpha * lost;
    r.compressed += (1.0 - alpha) * lost;
    r.contact.push_back(g);
    if (disturbed) disturbed->values()[static_cast<std::size_t>(g)] += static_cast<float>(lost);
  }
}

// Hands a cell's pending material to its neighbours in proportion to the
// weights `weight(m, k)` gives them (0: not a receiver). Returns false, keeping
// the material pending, when no neighbour takes any.
template <class Weight>
bool hand_on(Patch& p, int li, Weight weight) {
  const double amount = p.pending[li];
  if (!(amount > 0.0)) return true;
  std::array<int, 8> to{};
  std::array<double, 8> share{};
  int count = 0;
  double sum = 0.0;
  for (int k = 0; k < 8; ++k) {
    const int m = p.neighbour(li, k);
    if (m < 0) continue;
    const double wk = weight(m, k);
    if (wk > 0.0) to[count] = m, share[count++] = wk, sum += wk;
  }
  if (count == 0) return false;
  p.pending[li] = 0.0;
  for (int i = 0; i < count; ++i) p.pending[to[i]] += amount * (share[i] / sum);
  return true;
}

double along(const std::optional<Eigen::Vector2d>& drag, int k) {
  return drag ? kNeighbours8[k].dx * drag->x() + kNeighbours8[k].dy * drag->y() : 0.0;
}

// Material with nowhere to go under the object (a hole enclosed by the contact,
// the field's edge): compressed where it is, never stacked above the bottom.
void trap(Patch& p, int li, DisplacementReport& r) {
  r.displaced -= p.pending[li];
  r.compressed += p.pending[li];
  p.pending[li] = 0.0;
}

// Pressing: each connected contact region (8-neighbours) hands its displaced
// volume to the free cells of its ring, in proportion to the length of each
// ring cell's border with the region (1 for a side, 1/sqrt 2 for a corner, per
// metre). Paper 000, 3.4 routes the material down the distance transform to
// the contour; wherever it is routed, a press ends with each region's volume on
// its ring, and routing to the nearest edge gives a square's edge a supply
// shaped like the sector behind it (11 to 22 mm along one edge of a 12 cm box
// in mud, issue 32), where real prints have even rims. Spread evenly, straight
// edges get even rims and round objects round ones.
void spread_over_rings(Patch& p, DisplacementReport& r) {
  const int n = static_cast<int>(p.contact.size());
  std::vector<char> seen(p.contact.size(), 0);
  std::vector<double> weight(p.contact.size(), 0.0);
  std::vector<int> stack, ring;
  for (int start = 0; start < n; ++start) {
    if (!p.contact[start] || seen[start]) continue;
    double volume = 0.0;
    ring.clear();
    stack.assign(1, start);
    seen[start] = 1;
    while (!stack.empty()) {
      const int li = stack.back();
      stack.pop_back();
      volume += p.pending[li];
      p.pending[li] = 0.0;
      for (int k = 0; k < 8; ++k) {
        const int m = p.neighbour(li, k);
        if (m < 0) continue;
        if (p.contact[m]) {
          if (!seen[m]) seen[m] = 1, stack.push_back(m);
          continue;
        }
        if (weight[m] == 0.0) ring.push_back(m);
        weight[m] += 1.0 / p.length[k];
      }
    }
    double total = 0.0;
    for (int m : ring) total += weight[m];
    if (ring.empty() || !(total > 0.0)) {  // the region fills the window: the field's edge
      r.displaced -= volume, r.compressed += volume;
      continue;
    }
    for (int m : ring) p.pending[m] += volume * (weight[m] / total), weight[m] = 0.0;
  }
}

// Contact cells: spread over their rings (pressing) or from the back (dragging).
void displace_contact(Patch& p, const std::optional<Eigen::Vector2d>& drag, DisplacementReport& r) {
  std::vector<int> order;
  for (int li = 0; li < static_cast<int>(p.contact.size()); ++li)
    if (p.contact[li]) order.push_back(li);
  // Last resorts, in turn: any free neighbour, then any contact cell still to
  // come (higher in the order), then compression where it stands.
  std::vector<int> rank(p.contact.size(), -1);
  auto fallback = [&](int li) {
    if (hand_on(p, li, [&](int m, int k) { return p.contact[m] ? 0.0 : 1.0 / p.length[k]; }))
      return;
    if (hand_on(p, li, [&](int m, int k) { return rank[m] > rank[li] ? 1.0 / p.length[k] : 0.0; }))
      return;
    trap(p, li, r);
  };
  if (!drag) {
    spread_over_rings(p, r);
    return;
  }
  const double eps = 1e-9;
  auto key = [&](int li) {
    const int col = li % p.w.width, row = li / p.w.width;  // the cell's column and row
    return col * drag->x() + row * drag->y();
  };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
  for (std::size_t i = 0; i < order.size(); ++i) rank[order[i]] = static_cast<int>(i);
  for (int li : order)
    if (!hand_on(p, li, [&](int m, int k) {
          const double a = along(drag, k);
          return a > eps || (a >= -eps && !p.contact[m]) ? 1.0 : 0.0;
        }))
      fallback(li);
}

// Heave (issue 32; docs/marks.md, "Mud's heave"): a press into a material of
// heave H > 0 hands the volume on its ring (where spread_over_rings left it)
// to a band of width W = H B beside the contact, B the footing's width
// (footing_width; the band reaches kHeaveReach W): a free cell at distance
// d from the contact, x = d / (kHeaveReach W) < 1, takes a share in
// proportion to 1 - smoothstep(x) = 1 - 3x^2 + 2x^3, so the heave is highest
// at the wall and runs out with no slope left (a linear 1 - d / W ended in a
// crease that a low sun drew as a ring around mud prints), the same in every
// direction (straight edges give even
// bands, round prints round ones). A drag keeps the paper's flow (its bow
// wave goes ahead, not back into the trough).
void spread_heave(Patch& p, const MaterialField& materials, double footing) {
  const int n = static_cast<int>(p.contact.size());
  auto band = [&](int li) { return kHeaveReach * materials.at(p.global(li)).heave * footing; };
  double volume = 0.0;
  for (int li = 0; li < n; ++li)
    if (!p.contact[li] && p.pending[li] > 0.0 && p.outer[li] < band(li))
      volume += p.pending[li], p.pending[li] = 0.0;
  if (!(volume > 0.0)) return;
  std::vector<double> weight(p.contact.size(), 0.0);
  double total = 0.0;
  for (int li = 0; li < n; ++li) {
    const double w = band(li);
    if (p.contact[li] || !(p.outer[li] < w)) continue;
    const double x = p.outer[li] / w;
    weight[li] = 1.0 - x * x * (3.0 - 2.0 * x);
    total += weight[li];
  }
  for (int li = 0; li < n; ++li)
    if (weight[li] > 0.0) p.pending[li] += volume * (weight[li] / total);
}

// Free cells from the ring outwards: each keeps what fits under the object's
// bottom and pushes the rest on to the free cells farther out (never backwards
// when dragging if it can help it). The object's bottom is a hard ceiling
// (paper 000, 3.4, last paragraph): what cannot go anywhere is compressed. A
// press into a material that heaves first spreads its volume over the band
// (spread_heave). Cells with no free cell farther out in the window keep all
// that fits.
void settle_outside(Patch& p, terrain::Grid<double>& h, const BottomMap& bottom,
                    const MaterialField& materials, double footing,
                    const std::optional<Eigen::Vector2d>& drag, DisplacementReport& r,
                    terrain::Grid<float>* disturbed) {
  std::vector<int> order;
  for (int li = 0; li < static_cast<int>(p.contact.size()); ++li)
    if (!p.contact[li] && std::isfinite(p.outer[li])) order.push_back(li);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return p.outer[a] < p.outer[b]; });
  if (!drag && footing > 0.0) spread_heave(p, materials, footing);
  for (int li : order) {
    const double amount = p.pending[li];
    if (!(amount > 0.0)) continue;
    const int g = p.global(li);
    double& height = h.values()[static_cast<std::size_t>(g)];
    const double room = std::max(bottom.z[li] - height, 0.0);  // +inf: nothing above
    const double keep = std::min(amount, room);
    auto put = [&](double v) {
      height += v;
      if (v > 0.0) {
        r.received.push_back(g);
        if (disturbed) disturbed->values()[static_cast<std::size_t>(g)] += static_cast<float>(v);
      }
    };
    put(keep);
    p.pending[li] = amount - keep;
    // Outwards, in proportion to how much farther each neighbour is per metre.
    auto farther = [&](int m, int k) {
      return p.contact[m] ? 0.0 : std::max(p.outer[m] - p.outer[li], 0.0) / p.length[k];
    };
    if (hand_on(p, li, [&](int m, int k) { return along(drag, k) >= -1e-9 ? farther(m, k) : 0.0; }))
      continue;
    if (hand_on(p, li, farther)) continue;
    // Nowhere farther (the window's edge): what fits stays here.
    const double more = std::min(p.pending[li], std::max(room - keep, 0.0));
    if (more > 0.0) {
      put(more);
      p.pending[li] -= more;
    }
    if (p.pending[li] > 0.0) trap(p, li, r);
  }
}

// The footing's width B (m): the diameter of the widest disc inside the
// contact (twice the largest distance from a contact cell's centre to a free
// cell's, less a cell), so a strip's B is its width, a square's its side and
// a disc's its diameter. 0 when no material heaves (it is not needed).
double footing_width(const Patch& p, const MaterialField& materials, double dx, double dy) {
  double heave = 0.0;
  for (const Material& m : materials.table) heave = std::max(heave, m.heave);
  if (!(heave > 0.0)) return 0.0;
  std::vector<char> free(p.contact.size());
  for (std::size_t i = 0; i < free.size(); ++i) free[i] = !p.contact[i];
  const std::vector<double> inside = euclidean_distance(free, p.w.width, p.w.height, dx, dy, true);
  double deepest = 0.0;
  for (std::size_t i = 0; i < inside.size(); ++i)
    if (p.contact[i] && std::isfinite(inside[i])) deepest = std::max(deepest, inside[i]);
  return std::max(2.0 * deepest - std::min(dx, dy), std::min(dx, dy));
}

}  // namespace

DisplacementReport compress_and_displace(terrain::Grid<double>& heights, const BottomMap& bottom,
                                         const MaterialField& materials,
                                         const std::optional<Eigen::Vector2d>& drag,
                                         terrain::Grid<float>* disturbed, double dx, double dy) {
  DisplacementReport r;
  if (bottom.window.empty()) return r;
  Patch p;
  p.w = bottom.window;
  p.grid_w = heights.width();
  collide(heights, bottom, materials, p, r, disturbed);
  if (r.contact.empty()) return r;
  std::optional<Eigen::Vector2d> dir;
  if (drag && drag->norm() > 0) dir = drag->normalized();
  for (int k = 0; k < 8; ++k)
    p.length[k] = std::hypot(kNeighbours8[k].dx * dx, kNeighbours8[k].dy * dy);
  p.outer = euclidean_distance(p.contact, p.w.width, p.w.height, dx, dy, false);
  displace_contact(p, dir, r);
  settle_outside(p, heights, bottom, materials, footing_width(p, materials, dx, dy), dir, r,
                 disturbed);
  std::sort(r.received.begin(), r.received.end());
  return r;
}

}  // namespace drift::marks
