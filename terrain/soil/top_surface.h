// The top of the soil and of whatever it rests on, per column, as a height
// raster: how voxel soil joins the height-field stages (marks in a spoil
// heap, the renderer's terrain).
#pragma once

#include "terrain/grid.h"
#include "terrain/soil/soil_state.h"

namespace drift::soil {

// Height in voxels above the grid's floor of the highest pile or body top of
// column (x, y) (falling soil is ignored); 0 for an empty column.
float column_top(const SoilState& state, int x, int y);

// The raster of column tops in metres (origin.z + voxel_size * top), row 0 the
// northern edge (y = ny - 1), with `geo` as its georeference (a local one of
// the voxel size when geo is empty).
terrain::HeightField top_surface(const SoilState& state, const terrain::GeoReference& geo);

// The georeference of the grid's columns in its own metric frame: x east and
// y north in metres as the soil's meshes (row 0 at y = origin.y + ny h).
terrain::GeoReference grid_georeference(const terrain::Grid3Shape& shape);

// Ground for rendering around the soil: the height-field terrain under the
// grid (`terrain`, same columns; empty = the grid's flat floor), widened by
// `margin` columns on every side (edges repeated), in metres, georeferenced
// as the terrain if it has a CRS (a DEM's crop: the meshes' local x, y are
// then metres east and north of the crop's south-west corner), else as
// grid_georeference; widened by the margin.
terrain::HeightField ground_raster(const terrain::Grid3Shape& shape,
                                   const terrain::HeightField& terrain, int margin);

}  // namespace drift::soil
