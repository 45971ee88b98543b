// A DEM read strip by strip into 16-bit heights (issue 36 item 1; `drift
// render --height-bits 16`): the raster is read twice through GDAL, a strip of
// block rows at a time (terrain/raster_blocks.h), first for its lowest valid
// height (the local frame's origin and the nodata fill, as
// terrain/local_frame.h gives them in core), then to convert each strip to the
// local frame exactly as TerrainScene converts a DEM in core (nodata -> the
// lowest valid height, then h k - z0 in float) and quantise its block rows
// (QuantisedHeights::quantise_block_row) while only the strips in flight
// exist as floats. What the scene needs of the floats beyond the codes (the
// highest and lowest vertex, the ring's sums of the decoded heights) is
// gathered strip by strip in row-major order, so every bit matches the scene
// built from the whole DEM read as floats (height_bits_test.cpp).
//
// Memory: 2 B a cell of codes and 8 B a block of 16 x 16 cells, plus the
// strips in flight (kStripRows rows of floats a thread) and GDAL's block
// cache (64 MiB at most): with the tree built after, about 2.7 B a cell where
// the DEM read whole needed its 4 B of floats beside the codes.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>

#include "render/height_field.h"
#include "terrain/grid.h"

namespace drift::render {

struct StreamedHeights {
  QuantisedHeights heights;
  HeightGrid frame;  // the local frame of the vertices; z stays empty
  Eigen::Vector3d origin{0, 0, 0};
  terrain::GeoReference geo;
  Eigen::Vector3f highest{0, 0, 0}, lowest{0, 0, 0};  // local; the first in row-major order
  // Sums of the decoded heights and of their squares over every vertex, in
  // row-major order (render/surround.h, DemVertices).
  double sum = 0.0, sum_squares = 0.0;
};

// Vertex rows a strip reads at most (a multiple of QuantisedHeights::kBlock,
// and of 256, the tile side of the benchmark data, so GDAL decodes each tile
// row once).
inline constexpr int kStripRows = 256;

// Bytes the reading needs at its peak beside what the caller holds: the
// codes and ranges, the strips in flight on `threads` threads and GDAL's
// block cache, for a DEM of width x height vertices.
std::uint64_t streamed_heights_bytes(int width, int height, int threads);

// Reads band 1 of `dem` (heights scaled by `exaggeration`). Throws
// drift::Error naming the file for an unreadable raster, one under 2 x 2
// cells, rotated, with a non-positive cell size or all nodata.
StreamedHeights read_streamed_heights(const std::filesystem::path& dem, float exaggeration,
                                      int strip_rows = kStripRows);

}  // namespace drift::render
