// A height field as a triangle mesh: for `drift mesh` (terrain crops, marked
// ground, snow surfaces, any product raster laid out as heights).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "terrain/grid.h"
#include "terrain/mesh.h"
#include "terrain/mesh_rtin.h"
#include "terrain/raster_io.h"

namespace drift::terrain {

// Which cells of a north-up raster cover the box xmin,ymin,xmax,ymax of its CRS
// (the cells whose centres lie inside). Throws drift::Error naming `name` if the
// raster is rotated or the box misses it or holds fewer than 2 x 2 cells.
RasterWindow crop_window(const RasterHeader& header, const std::array<double, 4>& box,
                         const std::string& name);

// One vertex at the centre of every `step`-th cell (and the last row and
// column), two triangles a square, counter-clockwise seen from above; squares
// touching a nodata (NaN) cell are left out, and so are vertices no triangle
// uses. Positions are metres from `origin` = the first cell's centre at height
// 0 in the raster's CRS (floats hold centimetres then, whatever the CRS's
// magnitude); normals are the triangles' area-weighted. `attributes` are other
// rasters of the same grid, carried as named per-vertex attributes. Throws
// drift::Error if a grid differs or nothing is left.
Mesh height_field_mesh(const HeightField& heights, int step,
                       const std::vector<std::pair<std::string, HeightField>>& attributes = {});

// The same mesh simplified to at most `max_error` metres of vertical error at
// every cell centre (terrain/mesh_rtin.h: a right-triangulated irregular
// network, crack-free). Halves of cells with a nodata corner are left out.
// `measured_error`, if given, receives the largest error the mesh has;
// `before_list` is rtin_triangles' (terrain/mesh_rtin.h): the mesh's size
// once known, before it is allocated.
Mesh decimated_height_field_mesh(
    const HeightField& heights, double max_error,
    const std::vector<std::pair<std::string, HeightField>>& attributes = {},
    double* measured_error = nullptr, const RtinSizeCheck& before_list = {});

}  // namespace drift::terrain
