#include "pipeline/soil_scenario_file.h"

#include <cmath>
#include <sstream>

#include "pipeline/object_list.h"
#include "pipeline/toml_section.h"
#include "terrain/angles.h"
#include "terrain/bilinear.h"
#include "terrain/mesh_io.h"
#include "terrain/raster_io.h"
#include "terrain/soil/soil_parameters.h"
#include "terrain/soil/solid_mesh.h"

namespace drift::pipeline {

namespace {

constexpr const char* kDoc = "docs/soil.md";
constexpr double kBig = 1e7;
constexpr int kMaxColumns = 4096;  // [grid] size's bound on x and y, also under a DEM  // metres:
                                   // any coordinate a scenario can sensibly hold

soil::Primitive read_primitive(const toml::table* t, const std::filesystem::path& file,
                               const std::string& owner) {
  Section s(t, owner + ".primitive", file, kDoc);
  soil::Primitive p;
  const std::string shape = s.string("shape").value_or("");
  p.center = s.vector<3>("center", -kBig, kBig).value_or(Eigen::Vector3d::Zero());
  auto positive = [&](const char* key) {
    const double v = s.number(key, NAN, -kBig, kBig);
    if (!(v > 0)) s.invalid(key, "must be a positive number of metres");
    return v;
  };
  auto positive3 = [&](const char* key) {
    const auto v = s.vector<3>(key, -kBig, kBig);
    if (!v || !(v->array() > 0).all()) s.invalid(key, "must be three positive numbers of metres");
    return *v;
  };
  if (shape == "sphere") {
    p.kind = soil::PrimitiveKind::Sphere;
    p.size = {positive("radius"), 0, 0};
  } else if (shape == "ellipsoid") {
    p.kind = soil::PrimitiveKind::Ellipsoid;
    p.size = positive3("semi_axes");
  } else if (shape == "cuboid") {
    p.kind = soil::PrimitiveKind::Cuboid;
    p.size = positive3("half_extents");
  } else if (shape == "cylinder") {
    p.kind = soil::PrimitiveKind::Cylinder;
    p.size = {positive("radius"), 0, positive("half_height")};
  } else if (shape == "cone") {
    p.kind = soil::PrimitiveKind::Cone;
    p.size = {positive("radius"), 0, positive("height")};
  } else {
    s.invalid("shape", "is '" + shape +
                           "'; use sphere, ellipsoid, cuboid, cylinder or cone (and its sizes)");
  }
  s.finish();
  return p;
}

std::vector<soil::Primitive> read_primitives(Section& s, const std::filesystem::path& file,
                                             const std::string& owner) {
  std::vector<soil::Primitive> out;
  for (const toml::table* t : s.tables("primitive")) out.push_back(read_primitive(t, file, owner));
  if (out.empty()) s.invalid_table("needs at least one [[" + owner + ".primitive]]");
  return out;
}

void read_grid(const toml::table& root, const std::filesystem::path& file, soil::SoilScenario& sc) {
  Section s(root["grid"].as_table(), "grid", file, kDoc);
  const auto size = s.vector<3>("size", 0, 4096);  // x, y may be 0 under a dem: it sets them
  if (!size) s.invalid_table("needs size = [nx, ny, nz] (voxels)");
  for (int a = 0; a < 3; ++a)
    if ((*size)[a] != std::floor((*size)[a])) s.invalid("size", "must be whole numbers of voxels");
  sc.shape.nx = static_cast<int>((*size)[0]);
  sc.shape.ny = static_cast<int>((*size)[1]);
  sc.shape.nz = static_cast<int>((*size)[2]);
  sc.shape.voxel_size = s.number("voxel", 0.1, 1e-4, 1e4);
  sc.shape.origin = s.vector<3>("origin", -kBig, kBig).value_or(Eigen::Vector3d::Zero());
  s.finish();
}

void read_soil(const toml::table& root, const std::filesystem::path& file, soil::SoilScenario& sc) {
  Section s(root["soil"].as_table(), "soil", file, kDoc);
  const std::string type = s.string("type").value_or("dry_sand");
  try {
    sc.options.soil = soil::soil_preset(type);
  } catch (const Error& e) {
    s.invalid("type", std::string("is unknown: ") + e.what());
  }
  s.parameters(soil::soil_parameters(), sc.options);  // phi, cohesion, gamma, moisture
  s.finish();
}

void read_simulation(const toml::table& root, const std::filesystem::path& file,
                     soil::SoilScenario& sc) {
  Section s(root["simulation"].as_table(), "simulation", file, kDoc);
  soil::SoilOptions& o = sc.options;
  sc.steps = s.integer("steps", sc.steps, 0, soil::SoilScenario::kMaxSteps);
  s.parameters(soil::soil_parameters(), o);  // dt, gravity, propagation_iterations, ...
  const std::string overflow = s.string("overflow").value_or("up");
  if (overflow == "up")
    o.overflow = soil::OverflowHeuristic::Up;
  else if (overflow == "spread")
    o.overflow = soil::OverflowHeuristic::Spread;
  else if (overflow == "up_nine")
    o.overflow = soil::OverflowHeuristic::UpNine;
  else
    s.invalid("overflow", "is '" + overflow + "'; use up, spread or up_nine");
  o.slippage = s.boolean("slippage", o.slippage);
  s.finish();
}

// `window` with one pixel around it where the raster has one, so that the
// columns near the window's edge interpolate towards the DEM beyond it, as the
// renderer's surround does, instead of holding the edge pixel's height: held,
// the crop's edges stood up to 4 m off the DEM around it on Yarigatake's 41
// degree slopes (a step along the crop's outline in the render).
struct WindowWithApron {
  terrain::RasterWindow read;  // the window and its apron
  int left = 0, top = 0;       // apron pixels before the window
};
WindowWithApron with_apron(const terrain::RasterWindow& w, const terrain::RasterHeader& raster) {
  WindowWithApron a{w};
  const bool inside = w.width >= 1 && w.height >= 1 && w.x_off >= 0 && w.y_off >= 0 &&
                      w.x_off + w.width <= raster.width && w.y_off + w.height <= raster.height;
  if (!inside) return a;  // read_raster refuses it, in the user's numbers
  a.left = w.x_off > 0 ? 1 : 0;
  a.top = w.y_off > 0 ? 1 : 0;
  const int right = w.x_off + w.width < raster.width ? 1 : 0;
  const int bottom = w.y_off + w.height < raster.height ? 1 : 0;
  a.read = {w.x_off - a.left, w.y_off - a.top, w.width + a.left + right, w.height + a.top + bottom};
  return a;
}

// Degrees about x, then y, then z (world axes) as a rotation.
Eigen::Quaterniond rotation_from_degrees(const Eigen::Vector3d& deg) {
  const Eigen::Vector3d r = deg * terrain::kRadiansPerDegree<double>;
  return Eigen::Quaterniond(Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()));
}

std::string list(const Eigen::Vector4d& v) {
  std::ostringstream os;
  os << v[0] << ", " << v[1] << ", " << v[2] << ", " << v[3];
  return os.str();
}

// Beside a [terrain] dem, the DEM sets the grid's voxel (its cell over
// `upsample`), its x, y size (the window's) and its origin: a [grid] voxel,
// origin or x, y size that says otherwise was silently ignored (issue 34).
// Values equal to the DEM's are honoured; others are refused, naming the key,
// the value, what the DEM sets and the fix.
void refuse_grid_keys_set_by_dem(const toml::table& root, const std::filesystem::path& file,
                                 const terrain::Grid3Shape& shape,
                                 const terrain::RasterWindow& window, int up) {
  const toml::table* grid = root["grid"].as_table();
  if (!grid) return;
  Section g(grid, "grid", file, kDoc);
  std::ostringstream set_by;
  set_by << "the [terrain] dem sets it (" << window.width << " x " << window.height << " pixels of "
         << shape.voxel_size * up << " m, upsample " << up << ")";
  if (const auto v = g.number("voxel", shape.voxel_size, 0, 1e30);
      std::abs(v - shape.voxel_size) > 1e-9 * shape.voxel_size) {
    std::ostringstream what;
    what << "is " << v << " m, but " << set_by.str() << " to " << shape.voxel_size
         << " m; remove it, or set [terrain] upsample for finer voxels";
    g.invalid("voxel", what.str());
  }
  if (const auto size = g.vector<3>("size", 0, 4096);
      size && ((*size)[0] != 0 || (*size)[1] != 0) &&
      ((*size)[0] != shape.nx || (*size)[1] != shape.ny)) {
    std::ostringstream what;
    what << "is [" << (*size)[0] << ", " << (*size)[1] << ", " << (*size)[2] << "], but "
         << set_by.str() << " to x, y = " << shape.nx << ", " << shape.ny << "; write [0, 0, "
         << (*size)[2] << "]";
    g.invalid("size", what.str());
  }
  if (g.vector<3>("origin", -kBig, kBig))
    g.invalid("origin",
              "is set by the [terrain] dem (the window's corner, [terrain] depth below the "
              "lowest column); remove it");
}

// The DEM crop under the grid: `window` pixels of the raster, each cell split
// into `upsample` x `upsample` columns (bilinear over the window and its
// apron), the grid's floor `depth` metres below the lowest column.
void read_dem(Section& s, const toml::table& root, const std::filesystem::path& file,
              const std::filesystem::path& dem_override, soil::SoilScenario& sc) {
  const std::filesystem::path dem =
      dem_override.empty() ? file.parent_path() / *s.string("dem") : dem_override;
  const auto w = s.vector<4>("window", 0, 1e6);
  if (!w) s.invalid_table("with dem needs window = [x_off, y_off, width, height] (pixels)");
  // Pixels are whole: a fractional window was truncated without a word (issue 34).
  for (int i = 0; i < 4; ++i)
    if ((*w)[i] != std::floor((*w)[i]) || (i >= 2 && (*w)[i] < 1))
      s.invalid("window", "is [" + list(*w) +
                              "]; it must be whole pixels [x_off, y_off, width, height], width "
                              "and height at least 1: round them");
  const int up = s.integer("upsample", 1, 1, 64);
  const double depth = s.number("depth", 2.0, 0, 1e4);
  const terrain::RasterWindow window{static_cast<int>((*w)[0]), static_cast<int>((*w)[1]),
                                     static_cast<int>((*w)[2]), static_cast<int>((*w)[3])};
  // The grid's 4096 columns a side hold under a DEM too: a window upsampled
  // to 6400 a side was accepted, and one upsampled 64 times allocated its
  // heights (16 GiB) unchecked (issue 34).
  for (int i : {2, 3})
    if ((*w)[i] * up > kMaxColumns) {
      std::ostringstream what;
      what << "[" << list(*w) << "] with upsample " << up << " makes a grid of " << (*w)[2] * up
           << " x " << (*w)[3] * up << " columns; at most " << kMaxColumns
           << " a side: use a smaller window or upsample";
      s.invalid("window", what.str());
    }
  const WindowWithApron apron = with_apron(window, terrain::read_raster_header(dem));
  terrain::ReadOptions ro;
  ro.window = apron.read;
  const terrain::HeightField crop = terrain::read_raster(dem, ro);
  require_metric_crs(crop, dem);
  const double cell = crop.geo().cell_size_x();
  sc.shape.voxel_size = cell / up;
  sc.shape.nx = window.width * up;
  sc.shape.ny = window.height * up;
  terrain::HeightField heights(sc.shape.nx, sc.shape.ny, 0.0f, crop.geo());
  auto& gt = heights.geo().geotransform;
  // The window's corner, then columns of 1/up of a cell.
  gt[0] += apron.left * gt[1] + apron.top * gt[2];
  gt[3] += apron.left * gt[4] + apron.top * gt[5];
  for (int i : {1, 2, 4, 5}) gt[i] /= up;
  float lo = INFINITY;
  for (int r = 0; r < heights.height(); ++r) {
    for (int x = 0; x < heights.width(); ++x) {
      heights(x, r) = terrain::bilinear_clamped(crop, apron.left + (x + 0.5) / up - 0.5,
                                                apron.top + (r + 0.5) / up - 0.5);
      lo = std::min(lo, heights(x, r));
    }
  }
  sc.shape.origin = {0, 0, lo - depth};
  refuse_grid_keys_set_by_dem(root, file, sc.shape, window, up);
  sc.geo = heights.geo();
  sc.terrain.kind = soil::TerrainSource::Kind::HeightField;
  sc.terrain.heights = std::move(heights);
}

void read_terrain(const toml::table& root, const std::filesystem::path& file,
                  const std::filesystem::path& dem_override, soil::SoilScenario& sc) {
  if (!root.contains("terrain")) return;
  Section s(root["terrain"].as_table(), "terrain", file, kDoc);
  const std::string kind = s.string("kind").value_or("dem");
  if (kind == "dem") {
    if (!s.string("dem"))
      s.invalid_table("needs dem = \"FILE\" (a metric GeoTIFF) or kind = \"voxel\"");
    read_dem(s, root, file, dem_override, sc);
  } else if (kind == "voxel") {
    sc.terrain.kind = soil::TerrainSource::Kind::Voxel;
    sc.terrain.base = s.number("base", 0.5, -kBig, kBig);
    sc.terrain.seed = static_cast<unsigned long long>(s.integer("seed", 1, 0, 2147483647));
  } else {
    s.invalid("kind", "is '" + kind + "'; use dem or voxel");
  }
  s.finish();
}

void read_bodies(const toml::table& root, const std::filesystem::path& file,
                 soil::SoilScenario& sc) {
  Section top(&root, "", file, kDoc);
  for (const toml::table* t : top.tables("soil_body")) {
    Section s(t, "soil_body", file, kDoc);
    soil::SoilBody b;
    b.name = s.string("name").value_or("soil");
    b.position = s.vector<3>("position", -kBig, kBig).value_or(Eigen::Vector3d::Zero());
    b.on_ground = s.boolean("on_ground", false);
    // Its own moisture (thesis 5.3.4), over [soil] moisture: a wet layer
    // or region beside dry soil.
    if (const double m = s.number("moisture", -1, 0, 1); m >= 0) b.moisture = m;
    b.primitives = read_primitives(s, file, "soil_body");
    s.finish();
    sc.soil.push_back(std::move(b));
  }
  for (const toml::table* t : top.tables("body")) {
    Section s(t, "body", file, kDoc);
    soil::RigidObject b;
    b.name = s.string("name").value_or("body");
    // A closed triangle mesh (any format read_mesh takes, in the body's
    // frame; up as the format defines it unless mesh_y_up says), voxelised at
    // half a voxel; with or without primitives. read_mesh (not read_obj for
    // every extension) so that a glTF is read as one and its buffers pass the
    // input checks: a buffer on /dev/zero is refused naming the device, where
    // the OBJ reader had parsed the JSON as an OBJ "with no faces".
    if (const auto mesh = s.string("mesh")) {
      const bool up_given = t->contains("mesh_y_up");
      const bool y_up = s.boolean("mesh_y_up", false);
      const terrain::Mesh m =
          terrain::read_mesh(file.parent_path() / *mesh, !up_given ? terrain::UpAxis::Auto
                                                         : y_up    ? terrain::UpAxis::Y
                                                                   : terrain::UpAxis::Z);
      try {
        b.mesh = std::make_shared<soil::SolidMesh>(m, 0.5 * sc.shape.voxel_size, b.name);
      } catch (const Error& e) {
        s.invalid("mesh", std::string("'") + *mesh + "': " + e.what());
      }
    }
    if (b.mesh) {
      for (const toml::table* p : s.tables("primitive"))
        b.primitives.push_back(read_primitive(p, file, "body"));
    } else {
      b.primitives = read_primitives(s, file, "body");
    }
    // Turning: degrees a second about x, y, z (world axes) about the body's position.
    b.spin = s.vector<3>("spin", -1e5, 1e5).value_or(Eigen::Vector3d::Zero()) *
             terrain::kRadiansPerDegree<double>;
    for (const toml::table* k : s.tables("keyframe")) {
      Section ks(k, "body.keyframe", file, kDoc);
      soil::Keyframe f;
      f.time = ks.number("time", NAN, 0, 1e7);
      const auto p = ks.vector<3>("position", -kBig, kBig);
      if (!p) ks.invalid_table("needs position = [x, y, z] (m)");
      f.position = *p;
      // Degrees about x, then y, then z (world axes); slerped between keyframes.
      f.orientation = rotation_from_degrees(
          ks.vector<3>("rotation", -1e5, 1e5).value_or(Eigen::Vector3d::Zero()));
      ks.finish();
      b.path.push_back(f);
    }
    if (b.path.empty()) {
      b.path.push_back({0.0, s.vector<3>("position", -kBig, kBig).value_or(Eigen::Vector3d::Zero()),
                        rotation_from_degrees(
                            s.vector<3>("rotation", -1e5, 1e5).value_or(Eigen::Vector3d::Zero()))});
    } else {
      if (s.vector<3>("position", -kBig, kBig))
        s.invalid("position", "and [[body.keyframe]] both place the body; use one");
      if (s.vector<3>("rotation", -1e5, 1e5))
        s.invalid("rotation",
                  "and [[body.keyframe]] both turn the body; give each keyframe a rotation");
    }
    s.finish();
    soil::validate(b, file.string() + ": body");
    sc.bodies.push_back(std::move(b));
  }
}

}  // namespace

soil::SoilScenario read_soil_scenario(const std::filesystem::path& path,
                                      const std::filesystem::path& terrain) {
  const toml::table root = parse_toml_file(path, "soil scenario");
  soil::SoilScenario sc;
  sc.name = path.stem().string();
  for (const auto& [k, node] : root) {
    const std::string key(k.str());
    if (key != "grid" && key != "soil" && key != "simulation" && key != "terrain" &&
        key != "soil_body" && key != "body")
      throw Error(path.string() + ": unknown table or key '" + key +
                  "' (a scenario has [grid], [soil], [simulation], [terrain], [[soil_body]], "
                  "[[body]]; see docs/soil.md)");
  }
  if (!root.contains("grid") && !root.contains("terrain"))
    throw Error(path.string() + ": needs a [grid] (size, voxel) or a [terrain] with a dem");
  if (root.contains("grid")) read_grid(root, path, sc);
  read_terrain(root, path, terrain, sc);
  if (sc.shape.nx < 1 || sc.shape.ny < 1 || sc.shape.nz < 1)
    throw Error(path.string() +
                ": [grid] size must be at least 1 voxel on every axis (x and y "
                "may be 0 only with a [terrain] dem, which sets them)");
  read_soil(root, path, sc);
  read_simulation(root, path, sc);
  read_bodies(root, path, sc);
  return sc;
}

std::filesystem::path soil_scenario_dem(const std::filesystem::path& path) {
  const toml::table root = parse_toml_file(path, "soil scenario");
  const toml::node* dem = root["terrain"]["dem"].node();
  if (!dem || !dem->is_string()) return {};
  return path.parent_path() / **dem->as_string();  // as read_dem
}

}  // namespace drift::pipeline
