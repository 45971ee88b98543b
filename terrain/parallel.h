// Work over a list (tiles, runs of tiles, cells) that stays on the calling
// thread while the list is short, where TBB's overhead would outweigh the work
// (marks' small windows, the slow tail of a relaxation), and goes to TBB once
// it is long. Callers hand it items that write disjoint cells, so the result
// is the same bits either way and at any thread count. Slope relaxation
// (terrain/slope_relax) and snow's settling (snow/stabilise_grid) share it.
#pragma once

#include <tbb/parallel_for.h>

#include <cstddef>
#include <vector>

namespace drift::terrain {

// fn(k) for every k in [0, count), in parallel from `parallel_from` items on.
template <class Fn>
void for_each_index(std::size_t count, std::size_t parallel_from, const Fn& fn) {
  if (count < parallel_from) {
    for (std::size_t k = 0; k < count; ++k) fn(k);
    return;
  }
  tbb::parallel_for(std::size_t{0}, count, fn);
}

// fn(item) for every item of `items`, likewise.
template <class T, class Fn>
void for_each_item(const std::vector<T>& items, std::size_t parallel_from, const Fn& fn) {
  for_each_index(items.size(), parallel_from, [&](std::size_t k) { fn(items[k]); });
}

}  // namespace drift::terrain
