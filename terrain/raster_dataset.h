// For terrain's own sources that hold a GDAL dataset already (the warped grid
// of an import, kept in memory): read it as read_raster reads a file. Not for
// other modules: GDAL stays private to terrain.
#pragma once

#include <gdal_priv.h>

#include <filesystem>

#include "terrain/raster_io.h"

namespace drift::terrain {

// `name` is what errors call the data (the file it came from).
HeightField read_dataset(GDALDataset& dataset, const std::filesystem::path& name,
                         const ReadOptions& options = {});

}  // namespace drift::terrain
