#include "terrain/raster_io.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_minixml.h>
#include <cpl_string.h>
#include <gdal_priv.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "terrain/atomic_file.h"
#include "terrain/error.h"
#include "terrain/input_path.h"
#include "terrain/memory.h"

namespace drift::terrain {

namespace fs = std::filesystem;

namespace {

thread_local std::string g_last_gdal_message;

void CPL_STDCALL quiet_gdal_handler(CPLErr level, CPLErrorNum, const char* msg) {
  if (level >= CE_Warning && msg) g_last_gdal_message = msg;
}

struct DatasetCloser {
  void operator()(GDALDataset* ds) const {
    if (ds) GDALClose(GDALDataset::ToHandle(ds));
  }
};
using DatasetPtr = std::unique_ptr<GDALDataset, DatasetCloser>;

// A VRT names other rasters (its sources, and VRTs in turn): they are inputs
// too, checked as the VRT is before GDAL opens any of them, so a source that is
// a FIFO or a device cannot block or feed a run for ever (`drift info` had
// blocked on a VRT whose source was a FIFO). Paths through GDAL's virtual file
// systems (/vsizip/, /vsicurl/, ...) are GDAL's to check, but for /vsistdin/.
void check_vrt_sources(const fs::path& path, int depth = 0) {
  char head[16] = {};
  if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
    const std::size_t n = std::fread(head, 1, sizeof head - 1, f);
    std::fclose(f);
    head[n] = '\0';
  }
  if (std::string_view(head).find("<VRTDataset") == std::string_view::npos) return;
  if (depth > 8) {
    throw Error("cannot read raster '" + path.string() +
                "': VRTs nested more than 8 deep (a VRT naming itself?)");
  }
  std::unique_ptr<CPLXMLNode, decltype(&CPLDestroyXMLNode)> root(CPLParseXMLFile(path.c_str()),
                                                                 CPLDestroyXMLNode);
  if (!root) return;  // GDAL says what is wrong with it when it opens it
  std::vector<const CPLXMLNode*> stack = {root.get()};
  while (!stack.empty()) {
    const CPLXMLNode* node = stack.back();
    stack.pop_back();
    for (const CPLXMLNode* child = node->psChild; child; child = child->psNext) {
      if (child->eType == CXT_Element) stack.push_back(child);
    }
    if (node->eType != CXT_Element || !EQUAL(node->pszValue, "SourceFilename")) continue;
    const std::string name = CPLGetXMLValue(node, nullptr, "");
    if (name.rfind("/vsistdin", 0) == 0) {
      throw Error("cannot read raster '" + path.string() + "': its source '" + name +
                  "' is standard input; give a file");
    }
    if (name.empty() || name.rfind("/vsi", 0) == 0) continue;
    const bool relative = CPLTestBool(CPLGetXMLValue(node, "relativeToVRT", "0"));
    const fs::path source = relative ? path.parent_path() / name : fs::path(name);
    check_input_file(source, "source of VRT '" + path.string() + "',");
    check_vrt_sources(source, depth + 1);
  }
}

DatasetPtr open_raster(const fs::path& path) {
  ensure_gdal();
  check_input_file(path, "raster");
  check_vrt_sources(path);
  g_last_gdal_message.clear();
  auto* ds = static_cast<GDALDataset*>(
      GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
  if (!ds) {
    std::string why =
        g_last_gdal_message.empty() ? "not a raster format GDAL can read" : g_last_gdal_message;
    throw Error("cannot read '" + path.string() + "' as a raster: " + why +
                " (check the file is a DEM such as GeoTIFF, .hgt, DTED or ASCII grid)");
  }
  if (ds->GetRasterCount() < 1 || ds->GetRasterXSize() < 1 || ds->GetRasterYSize() < 1) {
    GDALClose(GDALDataset::ToHandle(ds));
    throw Error("cannot read '" + path.string() + "': it holds no raster band");
  }
  return DatasetPtr(ds);
}

GeoReference georeference_of(GDALDataset& ds, GDALRasterBand& band) {
  GeoReference geo;
  double gt[6];
  if (ds.GetGeoTransform(gt) == CE_None) {
    std::copy(gt, gt + 6, geo.geotransform.begin());
  }
  if (const OGRSpatialReference* srs = ds.GetSpatialRef()) {
    char* wkt = nullptr;
    const char* opts[] = {"FORMAT=WKT2_2018", nullptr};
    if (srs->exportToWkt(&wkt, opts) == OGRERR_NONE && wkt) geo.crs_wkt = wkt;
    CPLFree(wkt);
  }
  int has_nodata = 0;
  const double nd = band.GetNoDataValue(&has_nodata);
  if (has_nodata) geo.nodata = nd;
  return geo;
}

// A cell size of 0, NaN or infinity (or a NaN origin) makes every slope, area and
// position computed later meaningless.
void require_usable_georeference(const GeoReference& geo, const fs::path& path) {
  const auto& gt = geo.geotransform;
  bool finite = true;
  for (double v : gt) finite = finite && std::isfinite(v);
  const double dx = std::hypot(gt[1], gt[4]), dy = std::hypot(gt[2], gt[5]);
  if (!finite || !(dx > 0) || !(dy > 0) || !std::isfinite(1.0 / dx) || !std::isfinite(1.0 / dy)) {
    char text[200];
    std::snprintf(text, sizeof text, "%g, %g, %g, %g, %g, %g", gt[0], gt[1], gt[2], gt[3], gt[4],
                  gt[5]);
    throw Error("raster '" + path.string() + "' has an unusable georeference (geotransform " +
                text +
                "): cell sizes must be finite and non-zero; fix it with gdal_edit.py -a_ullr");
  }
}

// Heights beyond this are no ground in any unit (10,000 km; the deepest trench
// in millimetres still fits): an undeclared nodata such as -3.4e38, or a
// corrupt cell. Kept, such a cell overflowed the renderer's arithmetic (a black
// frame with exit 0) and every stage's slopes.
constexpr float kMaxAbsHeight = 1e7f;

std::string cell_place(const HeightField& grid, std::size_t i) {
  const std::size_t width = static_cast<std::size_t>(grid.width());
  return "column " + std::to_string(i % width) + ", row " + std::to_string(i / width);
}

// Infinite and absurd heights are refused rather than guessed at; NaN is
// nodata (filled by drift import, refused or handled by each stage).
void require_finite_cells(const HeightField& grid, const fs::path& path) {
  const float nd = grid.geo().nodata ? static_cast<float>(*grid.geo().nodata) : 0.0f;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const float v = grid.values()[i];
    if (!(std::fabs(v) > kMaxAbsHeight) || (grid.geo().nodata && v == nd)) continue;
    if (std::isinf(v)) {
      throw Error("raster '" + path.string() + "' holds an infinite height (" +
                  (v > 0 ? "+inf" : "-inf") + ") at " + cell_place(grid, i) +
                  "; declare it nodata or fix the cell");
    }
    char value[32];
    std::snprintf(value, sizeof value, "%g", static_cast<double>(v));
    throw Error("raster '" + path.string() + "' holds a height of " + value + " at " +
                cell_place(grid, i) + ", beyond any ground (|height| <= 1e7 m); if it marks " +
                "missing data, declare it nodata (gdal_edit.py -a_nodata " + value +
                "), else fix the cell");
  }
}

}  // namespace

void ensure_gdal() {
  static std::once_flag once;
  std::call_once(once, [] {
    GDALAllRegister();
    CPLSetErrorHandler(quiet_gdal_handler);
  });
}

std::string last_gdal_message() { return g_last_gdal_message; }

RasterHeader read_raster_header(const fs::path& path) {
  DatasetPtr ds = open_raster(path);
  GDALRasterBand* band = ds->GetRasterBand(1);
  RasterHeader h;
  h.width = ds->GetRasterXSize();
  h.height = ds->GetRasterYSize();
  h.bands = ds->GetRasterCount();
  h.driver = ds->GetDriver() ? ds->GetDriver()->GetDescription() : "";
  h.data_type = GDALGetDataTypeName(band->GetRasterDataType());
  h.geo = georeference_of(*ds, *band);
  return h;
}

HeightField read_raster(const fs::path& path, const ReadOptions& options) {
  DatasetPtr ds = open_raster(path);
  return read_dataset(*ds, path, options);
}

HeightField read_dataset(GDALDataset& dataset, const fs::path& path, const ReadOptions& options) {
  GDALDataset* ds = &dataset;
  if (options.band < 1 || options.band > ds->GetRasterCount()) {
    throw Error("cannot read band " + std::to_string(options.band) + " of '" + path.string() +
                "': it has " + std::to_string(ds->GetRasterCount()) + " band(s)");
  }
  GDALRasterBand* band = ds->GetRasterBand(options.band);
  RasterWindow win{0, 0, ds->GetRasterXSize(), ds->GetRasterYSize()};
  if (options.window) {
    win = *options.window;
    if (win.width < 1 || win.height < 1 || win.x_off < 0 || win.y_off < 0 ||
        win.x_off + win.width > ds->GetRasterXSize() ||
        win.y_off + win.height > ds->GetRasterYSize()) {
      throw Error("window " + std::to_string(win.width) + "x" + std::to_string(win.height) + "+" +
                  std::to_string(win.x_off) + "+" + std::to_string(win.y_off) + " lies outside '" +
                  path.string() + "' (" + std::to_string(ds->GetRasterXSize()) + "x" +
                  std::to_string(ds->GetRasterYSize()) + ")");
    }
  }
  // The heights, and GDAL's block cache, which keeps the blocks read (in the
  // file's type) until the file is closed, up to its cap (GDAL_CACHEMAX, 5 %
  // of memory by default): drift info on a float32 raster peaked at twice the
  // heights.
  const std::uint64_t cells = static_cast<std::uint64_t>(win.width) * win.height;
  const std::uint64_t cached =
      std::min(cells * static_cast<std::uint64_t>(
                           std::max(1, GDALGetDataTypeSizeBytes(band->GetRasterDataType()))),
               static_cast<std::uint64_t>(std::max<GIntBig>(0, GDALGetCacheMax64())));
  const std::uint64_t bytes = cells * sizeof(float) + cached;
  require_memory(bytes,
                 "raster '" + path.string() + "' (" + std::to_string(win.width) + " x " +
                     std::to_string(win.height) + " cells as float32)",
                 "crop it (drift import --crop) or resample it to a coarser cell size first");

  require_row_across_bands_memory(static_cast<std::uint64_t>(win.width), ds->GetRasterCount(),
                                  GDALGetDataTypeSizeBytes(band->GetRasterDataType()), path);

  GeoReference geo = georeference_of(*ds, *band);
  require_usable_georeference(geo, path);
  // Shift the geotransform to the window's origin.
  auto& gt = geo.geotransform;
  gt[0] += win.x_off * gt[1] + win.y_off * gt[2];
  gt[3] += win.x_off * gt[4] + win.y_off * gt[5];

  HeightField grid(win.width, win.height, 0.0f, geo);
  g_last_gdal_message.clear();
  const CPLErr err = band->RasterIO(GF_Read, win.x_off, win.y_off, win.width, win.height,
                                    grid.data(), win.width, win.height, GDT_Float32, 0, 0, nullptr);
  if (err != CE_None) {
    throw Error("cannot read the cells of '" + path.string() + "': " +
                (g_last_gdal_message.empty() ? std::string("read failed") : g_last_gdal_message) +
                " (the file may be truncated or corrupt)");
  }
  if (options.heights) require_finite_cells(grid, path);
  // Invalid cells become NaN in memory, whatever the file called them.
  if (geo.nodata) {
    const float nd = static_cast<float>(*geo.nodata);
    for (float& v : grid.values()) {
      if (v == nd) v = std::numeric_limits<float>::quiet_NaN();
    }
  }
  return grid;
}

void write_geotiff(const HeightField& grid, const fs::path& path, const WriteOptions& options) {
  ensure_gdal();
  if (grid.empty()) throw Error("cannot write '" + path.string() + "': the raster is empty");
  AtomicFile out(path);
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  if (!driver) throw Error("GDAL has no GTiff driver; reinstall libgdal");

  CPLStringList co;
  co.SetNameValue("COMPRESS", "DEFLATE");
  co.SetNameValue("PREDICTOR", "3");  // floating-point predictor: 2-3x smaller DEMs
  co.SetNameValue("BIGTIFF", "IF_SAFER");
  if (grid.width() >= 512 && grid.height() >= 512) {
    co.SetNameValue("TILED", "YES");
  }
  g_last_gdal_message.clear();
  DatasetPtr ds(driver->Create(out.temp_path().c_str(), grid.width(), grid.height(), 1, GDT_Float32,
                               co.List()));
  // GDAL's reasons never say that the output's folder is gone.
  const auto reason = [&path](const std::string& gdal) {
    std::error_code ec;
    const fs::path folder = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    return fs::is_directory(folder, ec) ? gdal : write_failure_reason(path, 0);
  };
  if (!ds) throw Error("cannot create '" + path.string() + "': " + reason(last_gdal_message()));
  const GeoReference& geo = grid.geo();
  double gt[6];
  std::copy(geo.geotransform.begin(), geo.geotransform.end(), gt);
  ds->SetGeoTransform(gt);
  if (!geo.crs_wkt.empty()) {
    OGRSpatialReference srs;
    if (srs.importFromWkt(geo.crs_wkt.c_str()) == OGRERR_NONE) ds->SetSpatialRef(&srs);
  }
  GDALRasterBand* band = ds->GetRasterBand(1);
  band->SetNoDataValue(std::numeric_limits<double>::quiet_NaN());
  if (!options.description.empty()) band->SetDescription(options.description.c_str());
  if (!options.units.empty()) band->SetUnitType(options.units.c_str());
  CPLErr err =
      band->RasterIO(GF_Write, 0, 0, grid.width(), grid.height(), const_cast<float*>(grid.data()),
                     grid.width(), grid.height(), GDT_Float32, 0, 0, nullptr);
  // Closing flushes: a failed close is a failed write.
  // GDAL 3.6's GDALClose returns nothing: watch the error state across it.
  CPLErrorReset();
  GDALClose(GDALDataset::ToHandle(ds.release()));
  if (CPLGetLastErrorType() == CE_Failure) err = CE_Failure;
  if (err != CE_None) {
    throw Error("cannot write '" + path.string() +
                "': " + reason(last_gdal_message() + " (disk full or not writable?)"));
  }
  out.commit();
}

void require_row_across_bands_memory(std::uint64_t width, int bands, int bytes_per_cell,
                                     const fs::path& path) {
  const double row = double(width) * std::max(bands, 1) * std::max(bytes_per_cell, 1);
  require_memory(static_cast<std::uint64_t>(std::min(row, 1.8e19)),
                 "raster '" + path.string() + "' (a row of " + std::to_string(width) +
                     " cells across its " + std::to_string(bands) + " bands)",
                 "keep band 1 only first: gdal_translate -b 1 IN OUT.tif");
}

}  // namespace drift::terrain
