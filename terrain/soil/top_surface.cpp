#include "terrain/soil/top_surface.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "terrain/soil/height_spans.h"

namespace drift::soil {

float column_top(const SoilState& s, int x, int y) {
  const std::size_t c = s.shape.column(x, y);
  HeightSpan spans[HeightSpans::kMaxSpans];
  const int n = build_column_spans(s.rho.data() + c, s.psi.data() + c, s.shape.nz, spans,
                                   HeightSpans::kMaxSpans);
  float top = 0;
  for (int i = 0; i < n; ++i)
    if (spans[i].type != SpanType::Falling) top = std::max(top, spans[i].top);
  return top;
}

terrain::HeightField top_surface(const SoilState& s, const terrain::GeoReference& geo) {
  const terrain::Grid3Shape& g = s.shape;
  terrain::HeightField out(g.nx, g.ny, 0.0f, geo);
  tbb::parallel_for(0, g.ny, [&](int y) {
    for (int x = 0; x < g.nx; ++x)
      out(x, g.ny - 1 - y) = static_cast<float>(g.origin.z() + g.voxel_size * column_top(s, x, y));
  });
  return out;
}

}  // namespace drift::soil
