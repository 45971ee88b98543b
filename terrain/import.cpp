#include "terrain/import.h"

#include <gdal_priv.h>
#include <gdal_utils.h>
#include <ogr_spatialref.h>

#include <cmath>
#include <memory>

#include "terrain/error.h"
#include "terrain/geodesy.h"
#include "terrain/memory.h"
#include "terrain/raster_dataset.h"
#include "terrain/raster_io.h"

namespace drift::terrain {

namespace fs = std::filesystem;

std::array<double, 2> metres_per_degree(double lat_deg);

namespace {

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// Crop boxes of positive, finite area; lon/lat boxes on the globe.
void check_crop_boxes(const ImportOptions& o) {
  if (o.crop) {
    const auto& b = *o.crop;
    for (double v : b) {
      if (!std::isfinite(v)) throw Error("--crop values must be finite numbers, got " + fmt(v));
    }
    if (!(b[0] < b[2] && b[1] < b[3])) {
      throw Error("--crop " + fmt(b[0]) + "," + fmt(b[1]) + "," + fmt(b[2]) + "," + fmt(b[3]) +
                  " has no area: give xmin,ymin,xmax,ymax with xmin < xmax and ymin < ymax");
    }
  }
  if (o.crop_lonlat) {
    const auto& b = *o.crop_lonlat;
    for (double v : b) {
      if (!std::isfinite(v)) {
        throw Error("--crop-lonlat values must be finite numbers, got " + fmt(v));
      }
    }
    if (b[1] < -90 || b[3] > 90 || b[0] < -180 || b[2] > 180) {
      throw Error("--crop-lonlat " + fmt(b[0]) + "," + fmt(b[1]) + "," + fmt(b[2]) + "," +
                  fmt(b[3]) +
                  " leaves the globe: longitudes lie in [-180, 180], latitudes in "
                  "[-90, 90]");
    }
    if (!(b[0] < b[2] && b[1] < b[3])) throw Error("--crop-lonlat needs W < E and S < N");
  }
}

// Metres per CRS unit along x of a raster kept in its CRS (1 for a local grid).
double metres_per_unit(const RasterHeader& h) {
  const double dx = std::fabs(h.geo.cell_size_x());
  return dx > 0 ? cell_size_metres(h.geo, h.width, h.height)[0] / dx : 1.0;
}

// The warped grid covers the crop box (or the source) at `cell`: checks it fits
// in memory three times over (GDAL's grid, ours, the nodata filling's copy)
// before GDAL allocates it. `unit_m` converts `cell` to metres.
void require_warp_memory(const RasterHeader& h, const ImportOptions& o, double unit_m, double cell,
                         const fs::path& path) {
  const auto metric = cell_size_metres(h.geo, h.width, h.height);
  double width_m = h.width * metric[0], height_m = h.height * metric[1];
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
  const double cell_m = cell * unit_m;
  const double cells = std::ceil(width_m / cell_m) * std::ceil(height_m / cell_m);
  const double bytes = cells * sizeof(float) * 3.0;
  const std::string what = "importing '" + path.string() + "' at " + fmt(cell_m) +
                           " m cells (about " + fmt(std::ceil(width_m / cell_m)) + " x " +
                           fmt(std::ceil(height_m / cell_m)) + ")";
  const std::string fix = "crop it (--crop, --crop-lonlat) or give a coarser --resample";
  if (!(cells < 2.0e9) || !std::isfinite(bytes)) {
    throw Error(what + " is too large a grid; " + fix);
  }
  require_memory(static_cast<std::uint64_t>(bytes), what, fix);
}

}  // namespace

// Metres per degree of latitude and longitude at `lat_deg` on WGS 84 (the
// standard series expansion, accurate to centimetres).
std::array<double, 2> metres_per_degree(double lat_deg) {
  const double lat = lat_deg * M_PI / 180.0;
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
  const int zone = std::clamp(static_cast<int>(std::floor((lon + 180.0) / 6.0)) + 1, 1, 60);
  return (lat >= 0 ? 32600 : 32700) + zone;
}

std::size_t fill_nodata(HeightField& g, const std::string& what) {
  std::size_t missing = 0;
  for (float v : g.values()) missing += std::isnan(v);
  if (missing == g.size()) {
    throw Error("'" + what + "' holds no valid height (every cell is nodata or NaN)");
  }
  std::size_t filled = 0;
  while (missing > 0) {
    HeightField next = g;
    for (int r = 0; r < g.height(); ++r) {
      for (int x = 0; x < g.width(); ++x) {
        if (!std::isnan(g(x, r))) continue;
        double sum = 0;
        int count = 0;
        for (int dr = -1; dr <= 1; ++dr)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, rr = r + dr;
            if (xx < 0 || rr < 0 || xx >= g.width() || rr >= g.height()) continue;
            if (!std::isnan(g(xx, rr))) sum += g(xx, rr), ++count;
          }
        if (count > 0) {
          next(x, r) = static_cast<float>(sum / count);
          ++filled;
          --missing;
        }
      }
    }
    g = std::move(next);
  }
  return filled;
}

ImportResult import_dem(const fs::path& path, const ImportOptions& o) {
  if (o.crop && o.crop_lonlat) throw Error("give --crop or --crop-lonlat, not both");
  if (o.resample_m && !(*o.resample_m > 0 && std::isfinite(*o.resample_m))) {
    throw Error("--resample must be a positive cell size in metres");
  }
  if (!(o.exaggeration > 0 && o.exaggeration <= 100)) {
    throw Error("--exaggerate must lie in (0, 100], got " + fmt(o.exaggeration));
  }
  check_crop_boxes(o);
  const RasterHeader header = read_raster_header(path);  // clear errors for bad files
  ImportResult result;
  result.report.push_back("read " + path.string() + ": " + header.driver + ", " +
                          std::to_string(header.width) + " x " + std::to_string(header.height));

  OGRSpatialReference srs;
  const bool has_crs =
      !header.geo.crs_wkt.empty() && srs.importFromWkt(header.geo.crs_wkt.c_str()) == OGRERR_NONE;
  const bool geographic = has_crs && srs.IsGeographic();
  const bool reproject = geographic && !o.keep_crs;

  // Warped into memory: no temporary file at all.
  std::vector<std::string> args = {"-of", "MEM",      "-ot",        "Float32",
                                   "-r",  "bilinear", "-dstnodata", "nan"};
  double cell = 0.0;
  if (reproject) {
    const auto lonlat = centre_lonlat(header.geo, header.width, header.height);
    const int epsg = utm_epsg(lonlat[0], lonlat[1]);
    // Square cells near the source's finest metric spacing.
    const auto metric = cell_size_metres(header.geo, header.width, header.height);
    const double cx = metric[0], cy = metric[1];
    cell = std::round(std::min(cx, cy) * 100.0) / 100.0;
    args.insert(args.end(), {"-t_srs", "EPSG:" + std::to_string(epsg)});
    result.report.push_back("reprojected " + std::string(srs.GetName() ? srs.GetName() : "?") +
                            " -> EPSG:" + std::to_string(epsg) + " (UTM zone " +
                            std::to_string(epsg % 100) + (epsg < 32700 ? "N" : "S") +
                            "), source cells " + fmt(std::round(cx * 100) / 100) + " x " +
                            fmt(std::round(cy * 100) / 100) + " m");
  } else {
    cell = std::fabs(header.geo.cell_size_x());
    if (geographic)
      result.report.push_back("kept the geographic CRS (--keep-crs): cells are degrees");
  }
  if (o.resample_m) cell = *o.resample_m;
  if (!(cell > 0)) throw Error("'" + path.string() + "' has no usable cell size");
  args.insert(args.end(), {"-tr", fmt(cell), fmt(cell)});
  if (o.crop) {
    const auto& b = *o.crop;
    args.insert(args.end(), {"-te", fmt(b[0]), fmt(b[1]), fmt(b[2]), fmt(b[3])});
    if (has_crs) args.insert(args.end(), {"-te_srs", header.geo.crs_wkt});
  } else if (o.crop_lonlat) {
    const auto& b = *o.crop_lonlat;
    if (!(b[0] < b[2] && b[1] < b[3])) throw Error("--crop-lonlat needs W < E and S < N");
    args.insert(args.end(),
                {"-te", fmt(b[0]), fmt(b[1]), fmt(b[2]), fmt(b[3]), "-te_srs", "EPSG:4326"});
  }
  require_warp_memory(header, o, reproject ? 1.0 : metres_per_unit(header), cell, path);

  ensure_gdal();
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::unique_ptr<GDALWarpAppOptions, decltype(&GDALWarpAppOptionsFree)> wopts(
      GDALWarpAppOptionsNew(argv.data(), nullptr), GDALWarpAppOptionsFree);
  if (!wopts) throw Error("internal: bad warp options for '" + path.string() + "'");
  GDALDatasetH src = GDALOpen(path.c_str(), GA_ReadOnly);
  if (!src) throw Error("cannot open '" + path.string() + "': " + last_gdal_message());
  int usage_error = 0;
  GDALDatasetH dst = GDALWarp("", nullptr, 1, &src, wopts.get(), &usage_error);
  GDALClose(src);
  if (!dst) {
    throw Error("cannot warp '" + path.string() + "': " + last_gdal_message() +
                (o.crop || o.crop_lonlat ? " (does the crop box overlap the DEM?)" : ""));
  }
  try {
    result.grid = read_dataset(*GDALDataset::FromHandle(dst), path);
  } catch (...) {
    GDALClose(dst);
    throw;
  }
  GDALClose(dst);
  result.report.push_back("grid " + std::to_string(result.grid.width()) + " x " +
                          std::to_string(result.grid.height()) + " cells of " + fmt(cell) +
                          (reproject || !geographic ? " m" : " deg"));

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

}  // namespace drift::terrain
