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

terrain::GeoReference grid_georeference(const terrain::Grid3Shape& g) {
  terrain::GeoReference geo;
  geo.geotransform = {g.origin.x(), g.voxel_size, 0.0, g.origin.y() + g.ny * g.voxel_size,
                      0.0,          -g.voxel_size};
  return geo;
}

terrain::HeightField ground_raster(const terrain::Grid3Shape& g, const terrain::HeightField& hf,
                                   int margin) {
  // A DEM's crop keeps the DEM's georeference (so the renderer can set the
  // whole DEM around it as its surround); else the grid's own frame.
  terrain::GeoReference geo = hf.geo().crs_wkt.empty() ? grid_georeference(g) : hf.geo();
  geo.nodata.reset();
  geo.geotransform[0] -= margin * g.voxel_size;
  geo.geotransform[3] += margin * g.voxel_size;
  terrain::HeightField out(g.nx + 2 * margin, g.ny + 2 * margin, static_cast<float>(g.origin.z()),
                           geo);
  if (hf.empty()) return out;
  for (int r = 0; r < out.height(); ++r)
    for (int x = 0; x < out.width(); ++x) out(x, r) = hf.clamped(x - margin, r - margin);
  return out;
}

}  // namespace drift::soil
