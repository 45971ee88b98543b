#include "terrain/marks/displacement.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <deque>

namespace drift::marks {

namespace {

constexpr std::array<std::array<int, 2>, 8> kNeighbours{
    {{-1, -1}, {0, -1}, {1, -1}, {-1, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}}};

// The window's cells with their state for one contact.
struct Patch {
  CellWindow w;
  int grid_w = 0;
  std::vector<char> contact;
  std::vector<double> pending;  // displaced material waiting to move (m)
  std::vector<int> inner;       // contact: chessboard distance to a free cell; free: 0
  std::vector<int> outer;       // free: distance from the contact (1 = ring); contact: 0

  int global(int li) const { return (w.row0 + li / w.width) * grid_w + w.col0 + li % w.width; }
  int neighbour(int li, int k) const {  // local index, or -1 outside the window
    const int x = li % w.width + kNeighbours[k][0], y = li / w.width + kNeighbours[k][1];
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

// Breadth-first chessboard distances: `from_contact` false gives contact cells
// their distance to the nearest free cell (the window's edge counts as free);
// true gives free cells their distance from the contact.
std::vector<int> distances(const Patch& p, bool from_contact) {
  const int n = p.w.width * p.w.height;
  std::vector<int> d(static_cast<std::size_t>(n), 0);
  std::deque<int> queue;
  for (int li = 0; li < n; ++li) {
    if (static_cast<bool>(p.contact[li]) == from_contact) continue;  // sources keep 0
    d[li] = INT_MAX;
    for (int k = 0; k < 8; ++k) {
      const int m = p.neighbour(li, k);
      if (m < 0 ? !from_contact : static_cast<bool>(p.contact[m]) == from_contact) {
        d[li] = 1;
        queue.push_back(li);
        break;
      }
    }
  }
  while (!queue.empty()) {
    const int li = queue.front();
    queue.pop_front();
    for (int k = 0; k < 8; ++k) {
      const int m = p.neighbour(li, k);
      if (m >= 0 && d[m] == INT_MAX) d[m] = d[li] + 1, queue.push_back(m);
    }
  }
  return d;
}

// Hands a cell's pending material in equal shares to the receivers that
// `accept` picks among its neighbours; with none, the cell keeps it.
template <class Accept>
void hand_on(Patch& p, int li, terrain::Grid<double>& h, Accept accept) {
  const double amount = p.pending[li];
  if (!(amount > 0.0)) return;
  std::array<int, 8> to{};
  int count = 0;
  for (int k = 0; k < 8; ++k) {
    const int m = p.neighbour(li, k);
    if (m >= 0 && accept(m, k)) to[count++] = m;
  }
  p.pending[li] = 0.0;
  if (count == 0) {
    h.values()[static_cast<std::size_t>(p.global(li))] += amount;
    return;
  }
  for (int i = 0; i < count; ++i) p.pending[to[i]] += amount / count;
}

double along(const std::optional<Eigen::Vector2d>& drag, int k) {
  return drag ? kNeighbours[k][0] * drag->x() + kNeighbours[k][1] * drag->y() : 0.0;
}

// Contact cells, deepest first (pressing) or from the back (dragging).
void displace_contact(Patch& p, terrain::Grid<double>& h,
                      const std::optional<Eigen::Vector2d>& drag) {
  std::vector<int> order;
  for (int li = 0; li < static_cast<int>(p.contact.size()); ++li)
    if (p.contact[li]) order.push_back(li);
  if (!drag) {
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return p.inner[a] > p.inner[b]; });
    for (int li : order) hand_on(p, li, h, [&](int m, int) { return p.inner[m] < p.inner[li]; });
    return;
  }
  const double eps = 1e-9;
  auto key = [&](int li) {
    const int col = li % p.w.width, row = li / p.w.width;  // the cell's column and row
    return col * drag->x() + row * drag->y();
  };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
  for (int li : order)
    hand_on(p, li, h, [&](int m, int k) {
      const double a = along(drag, k);
      return a > eps || (a >= -eps && !p.contact[m]);
    });
}

// Free cells from the ring outwards: each keeps what fits under the object's
// bottom and pushes the rest on.
void settle_outside(Patch& p, terrain::Grid<double>& h, const BottomMap& bottom,
                    const std::optional<Eigen::Vector2d>& drag, DisplacementReport& r,
                    terrain::Grid<float>* disturbed) {
  std::vector<int> order;
  for (int li = 0; li < static_cast<int>(p.contact.size()); ++li)
    if (!p.contact[li] && p.outer[li] != INT_MAX) order.push_back(li);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return p.outer[a] < p.outer[b]; });
  for (int li : order) {
    const double amount = p.pending[li];
    if (!(amount > 0.0)) continue;
    const int g = p.global(li);
    double& height = h.values()[static_cast<std::size_t>(g)];
    const double room = std::max(bottom.z[li] - height, 0.0);  // +inf: nothing above
    const double keep = std::min(amount, room);
    height += keep;
    p.pending[li] = amount - keep;
    if (keep > 0.0) {
      r.received.push_back(g);
      if (disturbed) disturbed->values()[static_cast<std::size_t>(g)] += static_cast<float>(keep);
    }
    hand_on(p, li, h, [&](int m, int k) {
      return !p.contact[m] && p.outer[m] == p.outer[li] + 1 && along(drag, k) >= -1e-9;
    });
  }
}

}  // namespace

DisplacementReport compress_and_displace(terrain::Grid<double>& heights, const BottomMap& bottom,
                                         const MaterialField& materials,
                                         const std::optional<Eigen::Vector2d>& drag,
                                         terrain::Grid<float>* disturbed) {
  DisplacementReport r;
  if (bottom.window.empty()) return r;
  Patch p;
  p.w = bottom.window;
  p.grid_w = heights.width();
  collide(heights, bottom, materials, p, r, disturbed);
  if (r.contact.empty()) return r;
  std::optional<Eigen::Vector2d> dir;
  if (drag && drag->norm() > 0) dir = drag->normalized();
  p.inner = distances(p, false);
  p.outer = distances(p, true);
  displace_contact(p, heights, dir);
  settle_outside(p, heights, bottom, dir, r, disturbed);
  std::sort(r.received.begin(), r.received.end());
  return r;
}

}  // namespace drift::marks
