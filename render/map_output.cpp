#include "render/map_output.h"

#include <gdal_priv.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <memory>

#include "render/image_io.h"
#include "terrain/atomic_file.h"
#include "terrain/error.h"
#include "terrain/raster_io.h"

namespace drift::render {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string xml_escape(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  AtomicFile file(path);
  write_all_bytes(file.temp_path(), text.data(), text.size(), path);
  file.commit();
}

}  // namespace

bool is_geotiff_path(const std::filesystem::path& path) {
  const std::string ext = lower(path.extension().string());
  return ext == ".tif" || ext == ".tiff";
}

std::vector<std::filesystem::path> map_png_sidecars(const std::filesystem::path& png) {
  std::filesystem::path world = png;
  world.replace_extension(".pgw");
  return {world, std::filesystem::path(png.string() + ".aux.xml")};
}

void write_map_geotiff(const Image& linear, const DisplayTransform& display,
                       const MapGeoreference& geo, const std::filesystem::path& path) {
  const std::vector<std::uint8_t> rgb = display_pixels(linear, display, path);
  terrain::ensure_gdal();
  AtomicFile file(path);
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
  if (!mem || !gtiff) throw Error("cannot write " + path.string() + ": GDAL has no GTiff driver");
  std::unique_ptr<GDALDataset> ds(
      mem->Create("", linear.width, linear.height, 3, GDT_Byte, nullptr));
  if (!ds) throw Error("cannot write " + path.string() + ": " + terrain::last_gdal_message());
  for (int b = 0; b < 3; ++b) {
    // Band b: every third byte from b (pixel spacing 3, line spacing 3 w).
    auto* data = const_cast<std::uint8_t*>(rgb.data()) + b;
    if (ds->GetRasterBand(b + 1)->RasterIO(GF_Write, 0, 0, linear.width, linear.height, data,
                                           linear.width, linear.height, GDT_Byte, 3,
                                           3 * static_cast<GSpacing>(linear.width)) != CE_None)
      throw Error("cannot write " + path.string() + ": " + terrain::last_gdal_message());
    ds->GetRasterBand(b + 1)->SetColorInterpretation(static_cast<GDALColorInterp>(GCI_RedBand + b));
  }
  std::array<double, 6> gt = geo.geotransform;
  ds->SetGeoTransform(gt.data());
  if (!geo.crs_wkt.empty()) ds->SetProjection(geo.crs_wkt.c_str());
  const char* options[] = {"COMPRESS=DEFLATE", "PHOTOMETRIC=RGB", nullptr};
  std::unique_ptr<GDALDataset> out(gtiff->CreateCopy(
      file.temp_path().c_str(), ds.get(), TRUE, const_cast<char**>(options), nullptr, nullptr));
  if (!out) throw Error("cannot write " + path.string() + ": " + terrain::last_gdal_message());
  out.reset();  // closes and flushes
  file.commit();
}

void write_map_png_sidecars(const std::filesystem::path& png, const MapGeoreference& geo) {
  const auto files = map_png_sidecars(png);
  const auto& gt = geo.geotransform;
  // A world file: x size, rotations, y size (negative), then the centre of
  // the first pixel (the geotransform gives its corner).
  char world[512];
  std::snprintf(world, sizeof world, "%.17g\n%.17g\n%.17g\n%.17g\n%.17g\n%.17g\n", gt[1], gt[4],
                gt[2], gt[5], gt[0] + 0.5 * gt[1] + 0.5 * gt[2], gt[3] + 0.5 * gt[4] + 0.5 * gt[5]);
  write_text(files[0], world);
  std::string aux = "<PAMDataset>\n";
  if (!geo.crs_wkt.empty())
    aux += "  <SRS dataAxisToSRSAxisMapping=\"1,2\">" + xml_escape(geo.crs_wkt) + "</SRS>\n";
  aux += "</PAMDataset>\n";
  write_text(files[1], aux);
}

}  // namespace drift::render
