#include "terrain/raster_blocks.h"

#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include "terrain/atomic_file.h"
#include "terrain/error.h"
#include "terrain/raster_io.h"

namespace drift::terrain {

namespace {

// As read_raster: heights beyond 10,000 km are no ground (terrain/raster_io.cpp).
constexpr float kMaxAbsHeight = 1e7f;
constexpr GIntBig kGdalCacheBytes = GIntBig{64} << 20;

}  // namespace

// An open GDAL dataset and its one band, closed with it: the reader's and the
// writer's handle.
struct GdalBand {
  GDALDataset* ds = nullptr;
  GDALRasterBand* band = nullptr;
  GdalBand() = default;
  GdalBand(const GdalBand&) = delete;
  GdalBand& operator=(const GdalBand&) = delete;
  ~GdalBand() {
    if (ds) GDALClose(GDALDataset::ToHandle(ds));
  }
};

struct RasterBlockReader::Dataset : GdalBand {};

RasterBlockReader::RasterBlockReader(const std::filesystem::path& path)
    : ds_(std::make_unique<Dataset>()), path_(path) {
  // The header read checks the file (missing, not a raster, broken VRT sources).
  const RasterHeader header = read_raster_header(path);
  width_ = header.width;
  height_ = header.height;
  geo_ = header.geo;
  // The pages above are the cache: GDAL's own block cache (5 % of the
  // machine's memory by default) is held to kGdalCacheBytes so that the
  // memory budget means what it says.
  GDALSetCacheMax64(std::min<GIntBig>(GDALGetCacheMax64(), kGdalCacheBytes));
  ds_->ds = static_cast<GDALDataset*>(
      GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
  if (!ds_->ds) throw Error("cannot open '" + path.string() + "' as a raster");
  ds_->band = ds_->ds->GetRasterBand(1);
}

RasterBlockReader::~RasterBlockReader() = default;

std::vector<float> RasterBlockReader::read(int x, int y, int w, int h, bool heights) const {
  if (w < 1 || h < 1 || x < 0 || y < 0 || x + w > width_ || y + h > height_) {
    throw Error("window " + std::to_string(w) + "x" + std::to_string(h) + "+" + std::to_string(x) +
                "+" + std::to_string(y) + " lies outside '" + path_.string() + "'");
  }
  std::vector<float> cells(static_cast<std::size_t>(w) * h);
  const CPLErr err =
      ds_->band->RasterIO(GF_Read, x, y, w, h, cells.data(), w, h, GDT_Float32, 0, 0, nullptr);
  if (err != CE_None) {
    const std::string why = last_gdal_message();
    throw Error("cannot read the cells of '" + path_.string() +
                "': " + (why.empty() ? std::string("read failed") : why) +
                " (the file may be truncated or corrupt)");
  }
  const bool has_nodata = geo_.nodata.has_value();
  const float nd = has_nodata ? static_cast<float>(*geo_.nodata) : 0.0f;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    float& v = cells[i];
    if (has_nodata && v == nd) {
      v = std::numeric_limits<float>::quiet_NaN();
    } else if (heights && std::fabs(v) > kMaxAbsHeight) {
      char value[32];
      std::snprintf(value, sizeof value, "%g", static_cast<double>(v));
      throw Error("raster '" + path_.string() + "' holds a height of " + value + " at column " +
                  std::to_string(x + static_cast<int>(i % w)) + ", row " +
                  std::to_string(y + static_cast<int>(i / w)) +
                  ", beyond any ground (|height| <= 1e7 m); declare it nodata or fix the cell");
    }
  }
  return cells;
}

HeightField RasterBlockReader::read_coarse(int max_side) const {
  const int step = std::max(1, (std::max(width_, height_) + max_side - 1) / max_side);
  const int w = std::max(1, width_ / step), h = std::max(1, height_ / step);
  GeoReference geo = geo_;
  auto& gt = geo.geotransform;
  const double sx = static_cast<double>(width_) / w, sy = static_cast<double>(height_) / h;
  gt[1] *= sx, gt[2] *= sy, gt[4] *= sx, gt[5] *= sy;
  HeightField coarse(w, h, 0.0f, geo);
  GDALRasterIOExtraArg extra;
  INIT_RASTERIO_EXTRA_ARG(extra);
  extra.eResampleAlg = GRIORA_NearestNeighbour;
  const CPLErr err = ds_->band->RasterIO(GF_Read, 0, 0, width_, height_, coarse.data(), w, h,
                                         GDT_Float32, 0, 0, &extra);
  if (err != CE_None) {
    throw Error("cannot read an overview of '" + path_.string() + "': " + last_gdal_message());
  }
  if (geo_.nodata) {
    const float nd = static_cast<float>(*geo_.nodata);
    for (float& v : coarse.values())
      if (v == nd) v = std::numeric_limits<float>::quiet_NaN();
  }
  return coarse;
}

namespace {

// GDAL's reasons never say that the output's folder is gone (as write_geotiff).
std::string write_reason(const std::filesystem::path& path, const std::string& gdal) {
  std::error_code ec;
  const std::filesystem::path folder = path.parent_path().empty() ? "." : path.parent_path();
  return std::filesystem::is_directory(folder, ec) ? gdal : write_failure_reason(path, 0);
}

}  // namespace

struct RasterBlockWriter::Dataset : GdalBand {};

RasterBlockWriter::RasterBlockWriter(const std::filesystem::path& path, int width, int height,
                                     const GeoReference& geo, const WriteOptions& options)
    : path_(path), ds_(std::make_unique<Dataset>()), width_(width), height_(height) {
  ensure_gdal();
  if (width < 1 || height < 1) throw Error("cannot write '" + path.string() + "': it is empty");
  file_ = std::make_unique<AtomicFile>(path);
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  if (!driver) throw Error("GDAL has no GTiff driver; reinstall libgdal");
  GDALSetCacheMax64(std::min<GIntBig>(GDALGetCacheMax64(), kGdalCacheBytes));
  CPLStringList co;
  co.SetNameValue("COMPRESS", "DEFLATE");
  co.SetNameValue("PREDICTOR", "3");
  co.SetNameValue("BIGTIFF", "IF_SAFER");
  co.SetNameValue("TILED", "YES");
  ds_->ds = driver->Create(file_->temp_path().c_str(), width, height, 1, GDT_Float32, co.List());
  if (!ds_->ds)
    throw Error("cannot create '" + path.string() +
                "': " + write_reason(path, last_gdal_message()));
  double gt[6];
  std::copy(geo.geotransform.begin(), geo.geotransform.end(), gt);
  ds_->ds->SetGeoTransform(gt);
  if (!geo.crs_wkt.empty()) {
    OGRSpatialReference srs;
    if (srs.importFromWkt(geo.crs_wkt.c_str()) == OGRERR_NONE) ds_->ds->SetSpatialRef(&srs);
  }
  ds_->band = ds_->ds->GetRasterBand(1);
  ds_->band->SetNoDataValue(std::numeric_limits<double>::quiet_NaN());
  if (!options.description.empty()) ds_->band->SetDescription(options.description.c_str());
  if (!options.units.empty()) ds_->band->SetUnitType(options.units.c_str());
}

RasterBlockWriter::~RasterBlockWriter() = default;

void RasterBlockWriter::write(int x, int y, int w, int h, const float* cells) {
  if (!ds_->ds || w < 1 || h < 1 || x < 0 || y < 0 || x + w > width_ || y + h > height_) {
    throw Error("internal: block " + std::to_string(w) + "x" + std::to_string(h) + "+" +
                std::to_string(x) + "+" + std::to_string(y) + " lies outside '" + path_.string() +
                "'");
  }
  const CPLErr err = ds_->band->RasterIO(GF_Write, x, y, w, h, const_cast<float*>(cells), w, h,
                                         GDT_Float32, 0, 0, nullptr);
  if (err != CE_None) {
    throw Error("cannot write '" + path_.string() +
                "': " + write_reason(path_, last_gdal_message() + " (disk full or not writable?)"));
  }
}

void RasterBlockWriter::finish() {
  // GDAL 3.6's GDALClose returns nothing: watch the error state across it.
  CPLErrorReset();
  GDALClose(GDALDataset::ToHandle(ds_->ds));
  ds_->ds = nullptr;
  if (CPLGetLastErrorType() == CE_Failure) {
    throw Error("cannot write '" + path_.string() +
                "': " + write_reason(path_, last_gdal_message() + " (disk full or not writable?)"));
  }
  file_->commit();
}

int block_cells(int requested, int fallback) {
  if (requested > 0) return requested;
  const char* env = std::getenv("DRIFT_BLOCK_CELLS");
  if (!env || !*env) return fallback;
  char* end = nullptr;
  const long v = std::strtol(env, &end, 10);
  if (*end != '\0' || v < 16 || v > 1048576) {
    throw Error("DRIFT_BLOCK_CELLS='" + std::string(env) +
                "' is no block size: give a whole number of cells in [16, 1048576], or unset it");
  }
  return static_cast<int>(v);
}

}  // namespace drift::terrain
