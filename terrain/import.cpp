#include "terrain/import.h"

#include <gdal_priv.h>
#include <gdal_utils.h>
#include <gdalwarper.h>
#include <ogr_spatialref.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "terrain/angles.h"
#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/memory.h"
#include "terrain/parameter.h"
#include "terrain/raster_blocks.h"
#include "terrain/raster_io.h"

namespace drift::terrain {

namespace fs = std::filesystem;

namespace {

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace

// Metres per degree of latitude and longitude at `lat_deg` on WGS 84 (the
// standard series expansion, accurate to centimetres).
std::array<double, 2> metres_per_degree(double lat_deg) {
  const double lat = terrain::radians(lat_deg);
  return {111412.84 * std::cos(lat) - 93.5 * std::cos(3 * lat),
          111132.92 - 559.82 * std::cos(2 * lat) + 1.175 * std::cos(4 * lat)};
}

std::array<double, 2> cell_size_metres(const GeoReference& geo, int width, int height,
                                       std::string* crs_name) {
  OGRSpatialReference srs;
  const double dx = std::fabs(geo.cell_size_x()), dy = std::fabs(geo.cell_size_y());
  if (geo.crs_wkt.empty() || srs.importFromWkt(geo.crs_wkt.c_str()) != OGRERR_NONE) {
    if (crs_name) *crs_name = "none (local grid, units taken as metres)";
    return {dx, dy};
  }
  if (crs_name) *crs_name = srs.GetName() ? srs.GetName() : "unnamed";
  if (!srs.IsGeographic()) {
    const double unit = srs.GetLinearUnits();
    return {dx * unit, dy * unit};
  }
  const auto m = metres_per_degree(centre_lonlat(geo, width, height)[1]);
  return {dx * m[0], dy * m[1]};
}

int utm_epsg(double lon, double lat) {
  // Clamped before the conversion: a longitude of 1e300 is no int (UBSan).
  const double z = std::floor((lon + 180.0) / 6.0) + 1.0;
  const int zone = std::isnan(z) ? 1 : static_cast<int>(std::clamp(z, 1.0, 60.0));
  return (lat >= 0 ? 32600 : 32700) + zone;
}

// Ring by ring as a breadth-first walk from the valid cells: each ring's cells
// take the mean of their neighbours of earlier rings, in the same order and
// arithmetic as a pass over the whole grid per ring, so the same bits, in time
// linear in the grid. A pass per ring is quadratic in a gap's width: a 1 x
// 17667 strip of nodata (found by fuzz_raster) takes over a minute so, and a
// DEM with a sea of nodata thousands of cells wide would never finish.
//
// A cell of ring r (its Chebyshev distance to the nearest valid cell) takes a
// value that depends on the cells within r of it only, and its ring is fixed
// by those same cells: the tiled import (import_dem_to_file) relies on it to
// fill a block from a window reaching r + 1 beyond each of its cells. `ring`,
// if given, receives each cell's ring (0: valid). Returns the number filled,
// or kNoValidCell (nothing changed) if the grid holds no valid cell.
namespace {
constexpr std::size_t kNoValidCell = static_cast<std::size_t>(-1);

std::size_t fill_rings(HeightField& g, std::vector<std::uint32_t>* ring_of) {
  const int w = g.width(), h = g.height();
  std::vector<std::uint8_t> known(g.size()), queued(g.size());
  std::size_t missing = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    known[i] = !std::isnan(g.values()[i]);
    missing += !known[i];
  }
  if (ring_of) ring_of->assign(g.size(), 0u);
  if (missing == g.size()) return kNoValidCell;
  const auto for_neighbours = [&](int x, int r, auto&& f) {
    for (int dr = -1; dr <= 1; ++dr)
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = x + dx, rr = r + dr;
        if (xx < 0 || rr < 0 || xx >= w || rr >= h) continue;
        f(static_cast<std::size_t>(rr) * w + xx);
      }
  };
  std::vector<std::size_t> ring;
  for (int r = 0; r < h; ++r)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(r) * w + x;
      if (known[i]) continue;
      for_neighbours(x, r, [&](std::size_t n) { queued[i] |= known[n]; });
      if (queued[i]) ring.push_back(i);
    }
  std::size_t filled = 0;
  std::uint32_t level = 0;
  std::vector<float> values;
  while (!ring.empty()) {
    ++level;
    values.assign(ring.size(), 0.0f);
    for (std::size_t k = 0; k < ring.size(); ++k) {
      double sum = 0;
      int count = 0;
      const int x = static_cast<int>(ring[k] % w), r = static_cast<int>(ring[k] / w);
      for_neighbours(x, r, [&](std::size_t n) {
        if (known[n]) sum += g.values()[n], ++count;
      });
      values[k] = static_cast<float>(sum / count);
    }
    std::vector<std::size_t> next;
    for (std::size_t k = 0; k < ring.size(); ++k) {
      g.values()[ring[k]] = values[k], known[ring[k]] = 1;
      if (ring_of) (*ring_of)[ring[k]] = level;
    }
    for (std::size_t i : ring) {
      for_neighbours(static_cast<int>(i % w), static_cast<int>(i / w), [&](std::size_t n) {
        if (!known[n] && !queued[n]) queued[n] = 1, next.push_back(n);
      });
    }
    filled += ring.size();
    ring = std::move(next);
  }
  return filled;
}
}  // namespace

std::size_t fill_nodata(HeightField& g, const std::string& what) {
  const std::size_t filled = fill_rings(g, nullptr);
  if (filled == kNoValidCell) {
    throw Error("'" + what + "' holds no valid height (every cell is nodata or NaN)");
  }
  return filled;
}

namespace {

// gdalwarp's arguments for an import and what they amount to.
struct WarpPlan {
  std::vector<std::string> args;
  double cell = 0.0;  // output cell size (metres, or degrees with keep_crs)
  bool has_crs = false, reproject = false, geographic = false;
  int epsg = 0;  // the UTM zone reprojected to
};

// The target CRS and cell size: a geographic DEM goes to the UTM zone of its
// centre at about its finest metric spacing, unless keep_crs.
void plan_grid(const fs::path& path, const RasterHeader& header, const ImportOptions& o,
               WarpPlan& plan, std::vector<std::string>& report) {
  OGRSpatialReference srs;
  plan.has_crs =
      !header.geo.crs_wkt.empty() && srs.importFromWkt(header.geo.crs_wkt.c_str()) == OGRERR_NONE;
  plan.geographic = plan.has_crs && srs.IsGeographic();
  plan.reproject = plan.geographic && !o.keep_crs;
  if (plan.reproject) {
    const auto lonlat = centre_lonlat(header.geo, header.width, header.height);
    if (!(std::fabs(lonlat[0]) <= 540.0 && std::fabs(lonlat[1]) <= 90.0)) {  // found by fuzzing
      throw Error("'" + path.string() + "' is in degrees but its centre (" + fmt(lonlat[0]) + ", " +
                  fmt(lonlat[1]) + ") lies off the globe; check its georeference (gdalinfo)");
    }
    const int epsg = utm_epsg(lonlat[0], lonlat[1]);
    plan.epsg = epsg;
    // Square cells near the source's finest metric spacing.
    const auto metric = cell_size_metres(header.geo, header.width, header.height);
    const double cx = metric[0], cy = metric[1];
    plan.cell = std::round(std::min(cx, cy) * 100.0) / 100.0;
    plan.args.insert(plan.args.end(), {"-t_srs", "EPSG:" + std::to_string(epsg)});
    report.push_back("reprojected " + std::string(srs.GetName() ? srs.GetName() : "?") +
                     " -> EPSG:" + std::to_string(epsg) + " (UTM zone " +
                     std::to_string(epsg % 100) + (epsg < 32700 ? "N" : "S") + "), source cells " +
                     fmt(std::round(cx * 100) / 100) + " x " + fmt(std::round(cy * 100) / 100) +
                     " m");
  } else {
    plan.cell = std::fabs(header.geo.cell_size_x());
    if (plan.geographic)
      report.push_back("kept the geographic CRS (--keep-crs): cells are degrees");
  }
}

// The whole warp: CRS, cell size and crop box.
WarpPlan plan_warp(const fs::path& path, const RasterHeader& header, const ImportOptions& o,
                   std::vector<std::string>& report) {
  WarpPlan plan;
  // Warped as a virtual dataset (a warped VRT, in memory): GDAL warps the
  // blocks a read asks for, no temporary file and no whole grid. One pass and
  // the tiled import read the same VRT, whose own 512 x 128 blocks fix every
  // warp chunk (and the approximate transformer's lines) in the grid's own
  // coordinates: a window reads the bits a whole read gives.
  plan.args = {"-of", "VRT", "-ot", "Float32", "-r", "bilinear", "-dstnodata", "nan"};
  plan_grid(path, header, o, plan, report);
  if (o.resample_m) plan.cell = *o.resample_m;
  if (!(plan.cell > 0)) throw Error("'" + path.string() + "' has no usable cell size");
  plan.args.insert(plan.args.end(), {"-tr", fmt(plan.cell), fmt(plan.cell)});
  if (o.crop) {
    const auto& b = *o.crop;
    plan.args.insert(plan.args.end(), {"-te", fmt(b[0]), fmt(b[1]), fmt(b[2]), fmt(b[3])});
    if (plan.has_crs) plan.args.insert(plan.args.end(), {"-te_srs", header.geo.crs_wkt});
  } else if (o.crop_lonlat) {
    const auto& b = *o.crop_lonlat;
    plan.args.insert(plan.args.end(),
                     {"-te", fmt(b[0]), fmt(b[1]), fmt(b[2]), fmt(b[3]), "-te_srs", "EPSG:4326"});
  }
  return plan;
}

// Metres per CRS unit along x of a raster kept in its CRS (1 for a local grid).
double metres_per_unit(const RasterHeader& h) {
  const double dx = std::fabs(h.geo.cell_size_x());
  return dx > 0 ? cell_size_metres(h.geo, h.width, h.height)[0] / dx : 1.0;
}

// The box in metres GDALWarp will cover when it reprojects the whole source
// (GDALSuggestedWarpOutput2, as GDALWarp itself computes it); false if GDAL
// cannot say. A tall strip of degrees near a zone's edge lies slanted in UTM:
// a 4 x 65535 cell strip became 150 million cells, where its own width and
// height at the cell size counted 320,000 (found by fuzz_raster).
bool reprojected_extent(const fs::path& path, int epsg, double& width_m, double& height_m) {
  OGRSpatialReference target;
  char* wkt = nullptr;
  if (target.importFromEPSG(epsg) != OGRERR_NONE || target.exportToWkt(&wkt) != OGRERR_NONE)
    return false;
  const std::string option = std::string("DST_SRS=") + wkt;
  CPLFree(wkt);
  std::unique_ptr<void, decltype(&GDALClose)> ds(GDALOpen(path.c_str(), GA_ReadOnly), GDALClose);
  if (!ds) return false;
  const char* options[] = {option.c_str(), nullptr};
  void* transform =
      GDALCreateGenImgProjTransformer2(ds.get(), nullptr, const_cast<char**>(options));
  if (!transform) return false;
  double gt[6], extent[4];
  int pixels = 0, lines = 0;
  const CPLErr err = GDALSuggestedWarpOutput2(ds.get(), GDALGenImgProjTransform, transform, gt,
                                              &pixels, &lines, extent, 0);
  GDALDestroyGenImgProjTransformer(transform);
  if (err != CE_None) return false;
  width_m = extent[2] - extent[0], height_m = extent[3] - extent[1];
  return std::isfinite(width_m) && std::isfinite(height_m);
}

// The warped grid covers the crop box (or the source) at the plan's cell: checks
// it fits in memory three times over (GDAL's grid, ours, the nodata filling's
// copy) before GDAL allocates it.
// Tiled (import_dem_to_file), only the grid's size is checked, against
// kMaxTiledCells: the memory is the blocks'.
constexpr double kMaxTiledCells = 17179869184.0;  // 2^34 cells (64 GiB of float32)
void require_warp_memory(const RasterHeader& h, const ImportOptions& o, const WarpPlan& plan,
                         const fs::path& path, bool tiled = false) {
  const auto metric = cell_size_metres(h.geo, h.width, h.height);
  double width_m = h.width * metric[0], height_m = h.height * metric[1];
  double warped_w = 0.0, warped_h = 0.0;
  if (plan.reproject && !o.crop && !o.crop_lonlat &&
      reprojected_extent(path, plan.epsg, warped_w, warped_h)) {
    width_m = std::max(width_m, warped_w), height_m = std::max(height_m, warped_h);
  }
  if (o.crop) {
    const auto& b = *o.crop;
    const double dx = std::fabs(h.geo.cell_size_x()), dy = std::fabs(h.geo.cell_size_y());
    width_m = (b[2] - b[0]) * (dx > 0 ? metric[0] / dx : 1.0);
    height_m = (b[3] - b[1]) * (dy > 0 ? metric[1] / dy : 1.0);
  } else if (o.crop_lonlat) {
    const auto& b = *o.crop_lonlat;
    const auto m = metres_per_degree(0.5 * (b[1] + b[3]));
    width_m = (b[2] - b[0]) * m[0];
    height_m = (b[3] - b[1]) * m[1];
  }
  const double cell_m = plan.cell * (plan.reproject ? 1.0 : metres_per_unit(h));
  const double columns = std::ceil(width_m / cell_m), rows = std::ceil(height_m / cell_m);
  const double bytes = columns * rows * sizeof(float) * 3.0;
  const std::string what = "importing '" + path.string() + "' at " + fmt(cell_m) +
                           " m cells (about " + fmt(columns) + " x " + fmt(rows) + ")";
  const std::string fix = "crop it (--crop, --crop-lonlat) or give a coarser --resample";
  if (!(columns * rows < (tiled ? kMaxTiledCells : 2.0e9)) || !std::isfinite(bytes)) {
    throw Error(what + " is too large a grid; " + fix);
  }
  if (tiled) return;
  require_memory(static_cast<std::uint64_t>(bytes), what, fix);
}

// The DEM is band 1; GDALWarp would warp every band into memory (GDAL 3.6 has
// no -b for warps), and a 400-byte TIFF declaring 65535 samples per pixel kept
// it busy for minutes growing a band list (found by fuzz_raster). A VRT of
// band 1 over the open file is warped instead.
GDALDatasetH first_band(GDALDatasetH file, const fs::path& path) {
  if (GDALGetRasterCount(file) <= 1) return file;
  const char* args[] = {"-of", "VRT", "-b", "1", nullptr};
  std::unique_ptr<GDALTranslateOptions, decltype(&GDALTranslateOptionsFree)> topts(
      GDALTranslateOptionsNew(const_cast<char**>(args), nullptr), GDALTranslateOptionsFree);
  int usage_error = 0;
  GDALDatasetH band1 = topts ? GDALTranslate("", file, topts.get(), &usage_error) : nullptr;
  if (!band1) {
    throw Error("cannot read band 1 of '" + path.string() + "': " + last_gdal_message());
  }
  return band1;
}

// The warped source as a GDAL dataset (a warped VRT over the open file).
struct Warped {
  GDALDatasetH file = nullptr, src = nullptr, dst = nullptr;
  Warped() = default;
  Warped(const Warped&) = delete;
  Warped& operator=(const Warped&) = delete;
  ~Warped() {
    if (dst) GDALClose(dst);
    if (src && src != file) GDALClose(src);
    if (file) GDALClose(file);
  }
  GDALDataset& dataset() const { return *GDALDataset::FromHandle(dst); }
};

// Sets up the warp (nothing is read yet).
void open_warped(Warped& w, const fs::path& path, const WarpPlan& plan, const ImportOptions& o) {
  ensure_gdal();
  std::vector<std::string> args = plan.args;
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::unique_ptr<GDALWarpAppOptions, decltype(&GDALWarpAppOptionsFree)> wopts(
      GDALWarpAppOptionsNew(argv.data(), nullptr), GDALWarpAppOptionsFree);
  if (!wopts) throw Error("internal: bad warp options for '" + path.string() + "'");
  w.file = GDALOpen(path.c_str(), GA_ReadOnly);
  if (!w.file) throw Error("cannot open '" + path.string() + "': " + last_gdal_message());
  w.src = first_band(w.file, path);
  int usage_error = 0;
  w.dst = GDALWarp("", nullptr, 1, &w.src, wopts.get(), &usage_error);
  if (!w.dst) {
    throw Error("cannot warp '" + path.string() + "': " + last_gdal_message() +
                (o.crop || o.crop_lonlat ? " (does the crop box overlap the DEM?)" : ""));
  }
}

// Runs the warp and reads the whole grid.
HeightField warp_to_grid(const fs::path& path, const WarpPlan& plan, const ImportOptions& o) {
  Warped w;
  open_warped(w, path, plan, o);
  return read_dataset(w.dataset(), path);
}

}  // namespace

void ImportOptions::validate() const {
  if (crop && crop_lonlat)
    throw ParameterError("crop_lonlat", "and crop are both given; give one, not both");
  if (resample_m) {
    require_field(*resample_m > 0 && std::isfinite(*resample_m), "resample_m", *resample_m,
                  "(0, inf) m, a cell size");
  }
  require_field(exaggeration > 0 && exaggeration <= 100, "exaggeration", exaggeration, "(0, 100]");
  if (block != 0)
    require_field(block >= 16 && block <= 1048576, "block", block, "[16, 1048576] cells, or 0");
  if (crop) {
    const auto& b = *crop;
    if (!(std::isfinite(b[0]) && std::isfinite(b[1]) && std::isfinite(b[2]) &&
          std::isfinite(b[3]) && b[0] < b[2] && b[1] < b[3])) {
      throw ParameterError("crop",
                           "has no area: give xmin,ymin,xmax,ymax with finite numbers, "
                           "xmin < xmax and ymin < ymax");
    }
  }
  if (crop_lonlat) {
    const auto& b = *crop_lonlat;
    if (!(b[1] >= -90 && b[3] <= 90 && b[0] >= -180 && b[2] <= 180)) {
      throw ParameterError("crop_lonlat",
                           "leaves the globe: longitudes lie in [-180, 180], "
                           "latitudes in [-90, 90]");
    }
    if (!(b[0] < b[2] && b[1] < b[3]))
      throw ParameterError("crop_lonlat", "needs west < east and south < north");
  }
}

namespace {

// What both imports start with: the options checked, the header read (clear
// errors for bad files), a row across the bands within memory, and the warp
// planned.
struct ImportStart {
  RasterHeader header;
  WarpPlan plan;
};
ImportStart start_import(const fs::path& path, const ImportOptions& o,
                         std::vector<std::string>& report) {
  o.validate();
  ImportStart start{read_raster_header(path), {}};
  const RasterHeader& header = start.header;
  require_row_across_bands_memory(
      static_cast<std::uint64_t>(header.width), header.bands,
      GDALGetDataTypeSizeBytes(GDALGetDataTypeByName(header.data_type.c_str())), path);
  report.push_back("read " + path.string() + ": " + header.driver + ", " +
                   std::to_string(header.width) + " x " + std::to_string(header.height));
  start.plan = plan_warp(path, header, o, report);
  return start;
}

}  // namespace

ImportResult import_dem(const fs::path& path, const ImportOptions& o) {
  ImportResult result;
  const auto [header, plan] = start_import(path, o, result.report);
  require_warp_memory(header, o, plan, path);
  result.grid = warp_to_grid(path, plan, o);
  result.report.push_back("grid " + std::to_string(result.grid.width()) + " x " +
                          std::to_string(result.grid.height()) + " cells of " + fmt(plan.cell) +
                          (plan.reproject || !plan.geographic ? " m" : " deg"));

  result.filled_cells = fill_nodata(result.grid, path.string());
  if (result.filled_cells > 0) {
    result.report.push_back("filled " + std::to_string(result.filled_cells) +
                            " nodata cells from their neighbours");
  }
  if (o.exaggeration != 1.0) {
    for (float& v : result.grid.values()) v = static_cast<float>(v * o.exaggeration);
    result.report.push_back("heights exaggerated x" + fmt(o.exaggeration));
  }
  result.grid.geo().nodata.reset();
  return result;
}

namespace {

// The tiled import's memory a window cell: the heights (4), the fill's known
// and queued flags (2), its ring index (4), ring lists and values (12 at
// worst), and the warper's buffers for the window (6, measured: a 3072^2 DEM
// in blocks of 2048 peaked 118 MB above a 32^2 one, 28 bytes a window cell).
constexpr std::uint64_t kFillBytesPerCell = 28;
// GDAL's block cache (held to 64 MiB by the block reader and writer) and the
// warper's chunk buffers (gdalwarp's default -wm, 64 MiB).
constexpr std::uint64_t kGdalBytes = std::uint64_t{128} << 20;
// The first fill halo: gaps narrower than this need no second read.
constexpr int kFirstFillHalo = 8;

struct Window {
  int x0, y0, x1, y1;  // [x0, x1) x [y0, y1), clipped to the grid
  std::uint64_t cells() const { return std::uint64_t(x1 - x0) * (y1 - y0); }
};

Window around(int bx, int by, int bw, int bh, int halo, int width, int height) {
  return {std::max(0, bx - halo), std::max(0, by - halo), std::min(width, bx + bw + halo),
          std::min(height, by + bh + halo)};
}

// Whether every cell of the block [bx, bx + bw) x [by, by + bh) got from the
// window the value a fill of the whole grid gives it: a cell of ring r needs
// the cells within r of it (fill_rings), so the window must reach r + 1
// beyond it on each side that is not the grid's border.
bool block_filled_exactly(const std::vector<std::uint32_t>& ring, const Window& win, int bx, int by,
                          int bw, int bh, int width, int height) {
  const int ww = win.x1 - win.x0;
  for (int y = by; y < by + bh; ++y)
    for (int x = bx; x < bx + bw; ++x) {
      const std::int64_t r = ring[static_cast<std::size_t>(y - win.y0) * ww + (x - win.x0)];
      if (r == 0) continue;
      if ((win.x0 > 0 && x - r - 1 < win.x0) || (win.y0 > 0 && y - r - 1 < win.y0) ||
          (win.x1 < width && x + r + 1 >= win.x1) || (win.y1 < height && y + r + 1 >= win.y1))
        return false;
    }
  return true;
}

}  // namespace

ImportFileResult import_dem_to_file(const fs::path& path, const fs::path& output,
                                    const ImportOptions& o, const ProgressFn& progress) {
  ImportFileResult result;
  const auto [header, plan] = start_import(path, o, result.report);
  require_warp_memory(header, o, plan, path, true);
  Warped warped;
  open_warped(warped, path, plan, o);
  GDALDataset& ds = warped.dataset();
  const int width = ds.GetRasterXSize(), height = ds.GetRasterYSize();
  const int block = block_cells(o.block, kImportBlock);
  result.width = width, result.height = height, result.block = block;
  const std::string what = "importing '" + path.string() + "' block by block (" +
                           std::to_string(block) + " cells a side)";
  const std::string fix = "give a smaller --block, or crop it (--crop, --crop-lonlat)";
  const auto require_window = [&](const Window& w, int halo) {
    require_memory(w.cells() * kFillBytesPerCell + kGdalBytes,
                   what + ", a window of " + std::to_string(w.x1 - w.x0) + " x " +
                       std::to_string(w.y1 - w.y0) + " cells (fill halo " + std::to_string(halo) +
                       ")",
                   fix);
  };
  // The peak of a block of the full size with the first halo.
  require_window(around(0, 0, block, block, kFirstFillHalo, width, height), kFirstFillHalo);
  // The warped grid's georeference, the nodata flag dropped (heights are whole).
  GeoReference geo = read_dataset(ds, path, {1, RasterWindow{0, 0, 1, 1}}).geo();
  geo.nodata.reset();
  RasterBlockWriter writer(output, width, height, geo, {"height (m)", "m"});
  const int bx_count = (width + block - 1) / block, by_count = (height + block - 1) / block;
  std::vector<float> out;
  std::vector<std::uint32_t> ring;
  bool any_valid = false;
  for (int j = 0; j < by_count; ++j)
    for (int i = 0; i < bx_count; ++i) {
      const int bx = i * block, by = j * block;
      const int bw = std::min(block, width - bx), bh = std::min(block, height - by);
      int halo = kFirstFillHalo;
      HeightField g;
      Window win{};
      for (;;) {
        win = around(bx, by, bw, bh, halo, width, height);
        require_window(win, halo);
        g = read_dataset(ds, path,
                         {1, RasterWindow{win.x0, win.y0, win.x1 - win.x0, win.y1 - win.y0}});
        const std::size_t filled = fill_rings(g, &ring);
        const bool whole = win.x0 == 0 && win.y0 == 0 && win.x1 == width && win.y1 == height;
        if (filled == kNoValidCell && whole) {
          throw Error("'" + path.string() +
                      "' holds no valid height (every cell is nodata or NaN)");
        }
        if (filled != kNoValidCell &&
            (whole || block_filled_exactly(ring, win, bx, by, bw, bh, width, height)))
          break;
        // A gap wider than the halo: read again with a wider one (the fill of
        // the wider window gives the whole grid's bits, fill_rings).
        halo *= 4;
      }
      result.max_fill_halo = std::max(result.max_fill_halo, halo);
      any_valid = true;
      out.resize(static_cast<std::size_t>(bw) * bh);
      const int ww = win.x1 - win.x0;
      for (int y = 0; y < bh; ++y)
        for (int x = 0; x < bw; ++x) {
          const std::size_t k = static_cast<std::size_t>(y + by - win.y0) * ww + (x + bx - win.x0);
          float v = g.values()[k];
          result.filled_cells += ring[k] > 0;
          if (o.exaggeration != 1.0) v = static_cast<float>(v * o.exaggeration);
          out[static_cast<std::size_t>(y) * bw + x] = v;
        }
      writer.write(bx, by, bw, bh, out.data());
      const double done = double(j * bx_count + i + 1) / (double(bx_count) * by_count);
      if (!progress(done, "")) throw Cancelled();
    }
  (void)any_valid;
  writer.finish();
  result.report.push_back(
      "grid " + std::to_string(width) + " x " + std::to_string(height) + " cells of " +
      fmt(plan.cell) + (plan.reproject || !plan.geographic ? " m" : " deg") + ", in " +
      std::to_string(bx_count * by_count) + " block(s) of " + std::to_string(block) + " cells");
  if (result.filled_cells > 0) {
    result.report.push_back("filled " + std::to_string(result.filled_cells) +
                            " nodata cells from their neighbours (fill halo up to " +
                            std::to_string(result.max_fill_halo) + " cells)");
  }
  if (o.exaggeration != 1.0) result.report.push_back("heights exaggerated x" + fmt(o.exaggeration));
  return result;
}

}  // namespace drift::terrain
