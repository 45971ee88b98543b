#include "terrain/mesh_io.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "terrain/atomic_file.h"
#include "terrain/error.h"
#include "terrain/input_path.h"
#include "terrain/memory.h"

namespace drift::terrain {

namespace fs = std::filesystem;

namespace {

// The most vertices one OBJ face may have. tinyobjloader's ear clipping is
// quadratic in a face's vertices (one face of 40,000 took 10 s, of 200,000 over a
// minute); at this bound a face costs at most a few milliseconds, so reading time
// stays proportional to the file's size.
constexpr std::size_t kMaxFaceVertices = 1024;

// A vertex coordinate as tinyobjloader would read it correctly: a plain decimal
// number (its own parser reads "0x1p+200" as 0 and "nan" as a finite value)
// that a float holds (1e39 would become infinity).
bool plain_finite_float(const std::string& word) {
  if (word.find_first_of("xXnNiI") != std::string::npos) return false;
  char* end = nullptr;
  const double v = std::strtod(word.c_str(), &end);
  return end != word.c_str() && *end == '\0' && std::isfinite(v) &&
         std::abs(v) <= static_cast<double>(std::numeric_limits<float>::max());
}

// The whole file, read after the input checks and a memory check on its size,
// so a device or a FIFO is never opened and no read is unbounded.
std::string read_obj_text(const fs::path& path) {
  check_input_file(path, "mesh");
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw Error("cannot read mesh '" + path.string() + "': " + ec.message());
  require_memory(4 * static_cast<std::uint64_t>(size), "mesh '" + path.string() + "'",
                 "use a smaller mesh");
  std::ifstream in(path, std::ios::binary);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), static_cast<std::streamsize>(size))) {
    throw Error("cannot read mesh '" + path.string() + "' (it changed while being read?)");
  }
  return text;
}

// Checks what tinyobjloader would read silently wrong or slowly, naming the line:
// vertex coordinates that are not finite plain numbers (with or without leading
// spaces: "  v nan 0 0" had read as 0) and faces of more than kMaxFaceVertices.
void check_obj_lines(const std::string& text, const fs::path& path) {
  std::istringstream lines(text);
  std::string line;
  for (std::size_t number = 1; std::getline(lines, line); ++number) {
    std::istringstream words(line);
    std::string key;
    if (!(words >> key)) continue;
    const auto where = [&] {
      return "mesh '" + path.string() + "', line " + std::to_string(number) + ": ";
    };
    if (key == "v") {
      std::string word;
      for (int k = 0; k < 3 && words >> word; ++k) {
        if (!plain_finite_float(word)) {
          throw Error(where() + "vertex coordinate '" + word +
                      "' is not a finite decimal number a float can hold");
        }
      }
    } else if (key == "f") {
      std::size_t corners = 0;
      for (std::string word; words >> word;) ++corners;
      if (corners > kMaxFaceVertices) {
        throw Error(where() + "a face of " + std::to_string(corners) +
                    " vertices; triangulate it in your modeller before export (at most " +
                    std::to_string(kMaxFaceVertices) + " vertices a face)");
      }
    }
  }
}

}  // namespace

Mesh read_obj(const fs::path& path, bool y_up) {
  const std::string text = read_obj_text(path);
  check_obj_lines(text, path);
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  // From memory, with no material text: a `mtllib` line names a file that
  // tinyobjloader would otherwise open unchecked (/dev/zero, a FIFO), and the
  // ground and renderer take no materials from an OBJ.
  if (!reader.ParseFromString(text, "", config)) {
    throw Error("cannot read mesh '" + path.string() + "': " + reader.Error() +
                " (is it a Wavefront OBJ file?)");
  }
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  Mesh mesh;
  const std::size_t n = attrib.vertices.size() / 3;
  mesh.positions.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float x = attrib.vertices[3 * i], y = attrib.vertices[3 * i + 1],
                z = attrib.vertices[3 * i + 2];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      throw Error("mesh '" + path.string() + "': vertex " + std::to_string(i + 1) +
                  " has a non-finite coordinate");
    }
    mesh.positions.emplace_back(y_up ? Eigen::Vector3f(x, -z, y) : Eigen::Vector3f(x, y, z));
  }
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const auto& idx = shape.mesh.indices;
    for (std::size_t f = 0; f + 2 < idx.size(); f += 3) {
      std::array<int, 3> tri{idx[f].vertex_index, idx[f + 1].vertex_index, idx[f + 2].vertex_index};
      for (int v : tri) {
        if (v < 0 || static_cast<std::size_t>(v) >= n) {
          throw Error("mesh '" + path.string() + "': shape '" + shape.name + "' refers to vertex " +
                      std::to_string(v + 1) + " of " + std::to_string(n));
        }
      }
      mesh.triangles.push_back(tri);
    }
  }
  if (mesh.triangles.empty()) {
    throw Error("mesh '" + path.string() + "' has no faces; export it with faces, not points");
  }
  return mesh;
}

void write_obj(const Mesh& mesh, const fs::path& path, bool y_up) {
  if (mesh.triangles.empty()) throw Error("cannot write '" + path.string() + "': empty mesh");
  const bool with_normals = mesh.normals.size() == mesh.positions.size();
  auto axes = [y_up](const Eigen::Vector3f& v) {
    return y_up ? Eigen::Vector3f(v.x(), v.z(), -v.y()) : v;
  };
  AtomicFile out(path);
  {
    std::ofstream f(out.temp_path());
    char line[160];
    std::snprintf(line, sizeof line, "# written by Driftscape (%s)\n# origin %.17g %.17g %.17g\n",
                  y_up ? "y up" : "z up", mesh.origin.x(), mesh.origin.y(), mesh.origin.z());
    f << line;
    for (const Eigen::Vector3f& p : mesh.positions) {
      const Eigen::Vector3f q = axes(p);
      std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", q.x(), q.y(), q.z());
      f << line;
    }
    if (with_normals) {
      for (const Eigen::Vector3f& n : mesh.normals) {
        const Eigen::Vector3f q = axes(n);
        std::snprintf(line, sizeof line, "vn %.6g %.6g %.6g\n", q.x(), q.y(), q.z());
        f << line;
      }
    }
    for (const auto& t : mesh.triangles) {
      if (with_normals) {
        std::snprintf(line, sizeof line, "f %d//%d %d//%d %d//%d\n", t[0] + 1, t[0] + 1, t[1] + 1,
                      t[1] + 1, t[2] + 1, t[2] + 1);
      } else {
        std::snprintf(line, sizeof line, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
      }
      f << line;
    }
    f.flush();
    if (!f)
      throw Error("cannot write '" + path.string() + "': " + write_failure_reason(path, errno));
  }
  out.commit();
}

void write_ply(const Mesh& mesh, const fs::path& path) {
  if (mesh.triangles.empty()) throw Error("cannot write '" + path.string() + "': empty mesh");
  const bool with_normals = mesh.normals.size() == mesh.positions.size();
  for (const auto& [name, values] : mesh.vertex_attributes) {
    if (values.size() != mesh.positions.size()) {
      throw Error("internal: attribute '" + name + "' has the wrong length for '" + path.string() +
                  "'");
    }
  }
  AtomicFile out(path);
  {
    std::ofstream f(out.temp_path(), std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\ncomment written by Driftscape\n";
    char origin[128];
    std::snprintf(origin, sizeof origin, "comment origin %.17g %.17g %.17g\n", mesh.origin.x(),
                  mesh.origin.y(), mesh.origin.z());
    f << origin;
    f << "element vertex " << mesh.positions.size() << "\n";
    f << "property float x\nproperty float y\nproperty float z\n";
    if (with_normals) f << "property float nx\nproperty float ny\nproperty float nz\n";
    for (const auto& attribute : mesh.vertex_attributes) {
      f << "property float " << attribute.first << "\n";
    }
    f << "element face " << mesh.triangles.size() << "\n";
    f << "property list uchar int vertex_indices\nend_header\n";
    auto put = [&f](const auto& v) { f.write(reinterpret_cast<const char*>(&v), sizeof v); };
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      for (int k = 0; k < 3; ++k) put(mesh.positions[i][k]);
      if (with_normals) {
        for (int k = 0; k < 3; ++k) put(mesh.normals[i][k]);
      }
      for (const auto& attribute : mesh.vertex_attributes) put(attribute.second[i]);
    }
    for (const auto& tri : mesh.triangles) {
      put(static_cast<unsigned char>(3));
      for (int v : tri) put(v);
    }
    f.flush();
    if (!f)
      throw Error("cannot write '" + path.string() + "': " + write_failure_reason(path, errno));
  }
  out.commit();
}

std::vector<Mesh> split_by_attribute(const Mesh& mesh, const std::string& name) {
  const std::vector<float>* key = mesh.attribute(name);
  if (!key) throw Error("the mesh has no per-vertex '" + name + "' attribute to split by");
  int parts = 0;
  for (float v : *key) parts = std::max(parts, static_cast<int>(v) + 1);
  std::vector<Mesh> out(static_cast<std::size_t>(parts));
  std::vector<int> part_of(mesh.positions.size()), index_in(mesh.positions.size());
  for (auto& part : out) {
    part.origin = mesh.origin;
    for (const auto& [n, values] : mesh.vertex_attributes)
      part.vertex_attributes.emplace_back(n, std::vector<float>{});
  }
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const int k = std::max(0, static_cast<int>((*key)[v]));
    Mesh& part = out[static_cast<std::size_t>(k)];
    part_of[v] = k;
    index_in[v] = static_cast<int>(part.positions.size());
    part.positions.push_back(mesh.positions[v]);
    if (mesh.normals.size() == mesh.positions.size()) part.normals.push_back(mesh.normals[v]);
    for (std::size_t a = 0; a < mesh.vertex_attributes.size(); ++a)
      part.vertex_attributes[a].second.push_back(mesh.vertex_attributes[a].second[v]);
  }
  for (const auto& t : mesh.triangles) {
    const int k = part_of[static_cast<std::size_t>(t[0])];
    if (part_of[static_cast<std::size_t>(t[1])] != k ||
        part_of[static_cast<std::size_t>(t[2])] != k)
      continue;
    out[static_cast<std::size_t>(k)].triangles.push_back(
        {index_in[static_cast<std::size_t>(t[0])], index_in[static_cast<std::size_t>(t[1])],
         index_in[static_cast<std::size_t>(t[2])]});
  }
  return out;
}

namespace {

// What a PLY header declares (only what drift writes: binary little-endian,
// float vertex properties, triangles as uchar-counted int lists).
struct PlyHeader {
  std::vector<std::string> properties;  // vertex properties, in order
  std::size_t vertices = 0, faces = 0;
  Eigen::Vector3d origin{0, 0, 0};  // "comment origin X Y Z"
};

using PlyError = std::function<Error(const std::string&)>;

// One header line after "ply"; `element` is the element being declared.
void read_ply_header_line(const std::string& line, std::string& element, PlyHeader& h,
                          const PlyError& bad) {
  std::istringstream in(line);
  std::string word;
  in >> word;
  if (word == "format") {
    std::string format;
    in >> format;
    if (format != "binary_little_endian") throw bad("format '" + format + "'");
  } else if (word == "comment") {
    std::string key;
    double x, y, z;
    if (in >> key && key == "origin" && in >> x >> y >> z) h.origin = {x, y, z};
  } else if (word == "element") {
    in >> element;
    std::size_t count = 0;
    in >> count;
    if (element == "vertex")
      h.vertices = count;
    else if (element == "face")
      h.faces = count;
    else
      throw bad("element '" + element + "'");
  } else if (word == "property") {
    std::string type;
    in >> type;
    if (element == "vertex") {
      std::string name;
      in >> name;
      if (type != "float") throw bad("vertex property '" + name + "' of type " + type);
      h.properties.push_back(name);
    } else if (line != "property list uchar int vertex_indices") {
      throw bad("face property '" + line + "'");
    }
  }
}

PlyHeader read_ply_header(std::istream& f, const PlyError& bad) {
  std::string line;
  if (!std::getline(f, line) || line != "ply") throw bad("not a PLY file");
  PlyHeader h;
  std::string element;
  while (std::getline(f, line) && line != "end_header") read_ply_header_line(line, element, h, bad);
  if (line != "end_header") throw bad("no end_header");
  // Before anything is sized by the vertex count: a header of 889,850,951
  // vertices and no properties passed the size check below (0 bytes a row)
  // and had 3.6 GB allocated (fuzz_ply).
  for (const char* axis : {"x", "y", "z"}) {
    if (std::find(h.properties.begin(), h.properties.end(), axis) == h.properties.end())
      throw bad("the header declares no float vertex property '" + std::string(axis) + "'");
  }
  // What the header declares must be in the file, before anything is allocated.
  const std::streampos body = f.tellg();
  f.seekg(0, std::ios::end);
  const auto left = static_cast<std::uintmax_t>(f.tellg() - body);
  f.seekg(body);
  const std::uintmax_t needed = static_cast<std::uintmax_t>(h.vertices) * h.properties.size() * 4 +
                                static_cast<std::uintmax_t>(h.faces) * 13;
  if (h.vertices > (std::size_t{1} << 31) || h.faces > (std::size_t{1} << 31) || needed > left) {
    throw bad("the header declares " + std::to_string(h.vertices) + " vertices and " +
              std::to_string(h.faces) + " faces, more than the file holds (truncated?)");
  }
  return h;
}

// The vertex rows into positions, normals and named attributes.
void read_ply_vertices(std::istream& f, const PlyHeader& h, Mesh& mesh, const PlyError& bad) {
  const std::size_t vertices = h.vertices;
  std::vector<float> row(h.properties.size());
  std::vector<std::vector<float>> columns(h.properties.size(), std::vector<float>(vertices));
  for (std::size_t v = 0; v < vertices; ++v) {
    if (!f.read(reinterpret_cast<char*>(row.data()),
                static_cast<std::streamsize>(row.size() * sizeof(float)))) {
      throw bad("truncated vertex data");
    }
    for (std::size_t p = 0; p < row.size(); ++p) columns[p][v] = row[p];
  }
  auto column = [&](const char* name) -> std::vector<float>* {
    for (std::size_t p = 0; p < h.properties.size(); ++p)
      if (h.properties[p] == name) return &columns[p];
    return nullptr;
  };
  const auto *x = column("x"), *y = column("y"), *z = column("z");  // read_ply_header checked
  mesh.positions.resize(vertices);
  for (std::size_t v = 0; v < vertices; ++v) {
    mesh.positions[v] = {(*x)[v], (*y)[v], (*z)[v]};
    if (!mesh.positions[v].allFinite()) {
      throw bad("vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
  }
  const auto *nx = column("nx"), *ny = column("ny"), *nz = column("nz");
  if (nx && ny && nz) {
    mesh.normals.resize(vertices);
    for (std::size_t v = 0; v < vertices; ++v) mesh.normals[v] = {(*nx)[v], (*ny)[v], (*nz)[v]};
  }
  for (std::size_t p = 0; p < h.properties.size(); ++p) {
    const std::string& n = h.properties[p];
    if (n != "x" && n != "y" && n != "z" && n != "nx" && n != "ny" && n != "nz")
      mesh.vertex_attributes.emplace_back(n, std::move(columns[p]));
  }
}

void read_ply_faces(std::istream& f, const PlyHeader& h, Mesh& mesh, const PlyError& bad) {
  mesh.triangles.resize(h.faces);
  for (std::size_t t = 0; t < h.faces; ++t) {
    unsigned char count = 0;
    int idx[3];
    if (!f.read(reinterpret_cast<char*>(&count), 1) || count != 3 ||
        !f.read(reinterpret_cast<char*>(idx), sizeof idx)) {
      throw bad("face " + std::to_string(t) + " is not a triangle or is truncated");
    }
    for (int k = 0; k < 3; ++k) {
      if (idx[k] < 0 || static_cast<std::size_t>(idx[k]) >= h.vertices)
        throw bad("face " + std::to_string(t) + " names vertex " + std::to_string(idx[k]));
    }
    mesh.triangles[t] = {idx[0], idx[1], idx[2]};
  }
}

}  // namespace

Mesh read_ply(const fs::path& path) {
  check_input_file(path, "mesh");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw Error("cannot read mesh '" + path.string() + "': no such file");
  const PlyError bad = [&](const std::string& what) {
    return Error("cannot read mesh '" + path.string() + "': " + what +
                 " (drift reads the binary PLY files it writes; convert others to OBJ)");
  };
  const PlyHeader header = read_ply_header(f, bad);
  Mesh mesh;
  mesh.origin = header.origin;
  read_ply_vertices(f, header, mesh, bad);
  read_ply_faces(f, header, mesh, bad);
  return mesh;
}

}  // namespace drift::terrain

namespace drift::terrain {

namespace {

std::string lower_ext(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace

Mesh read_mesh(const fs::path& path, UpAxis up) {
  const std::string ext = lower_ext(path);
  // OBJ and PLY keep their own readers: both are fuzzed (tests/fuzz) and refuse
  // what Assimp would read silently (OBJ's "nan" and hex coordinates, a PLY
  // header larger than its file); PLY also carries drift's named attributes.
  if (ext == ".obj") return read_obj(path, up == UpAxis::Y);
  if (ext == ".ply") {
    Mesh m = read_ply(path);
    if (up == UpAxis::Y) {
      for (auto& p : m.positions) p = Eigen::Vector3f(p.x(), -p.z(), p.y());
      for (auto& n : m.normals) n = Eigen::Vector3f(n.x(), -n.z(), n.y());
    }
    return m;
  }
  return read_mesh_assimp(path, up);
}

bool is_mesh_output(const fs::path& path) {
  const std::string ext = lower_ext(path);
  return ext == ".ply" || ext == ".obj" || ext == ".glb" || ext == ".gltf" || ext == ".stl" ||
         ext == ".fbx";
}

std::uint64_t mesh_and_write_bytes(const fs::path& path, std::uint64_t vertices,
                                   std::uint64_t triangles, std::size_t attributes) {
  const std::uint64_t v = vertices, t = triangles, a = attributes;
  // The mesh: position and normal (12 + 12), a float per attribute; 3 indices a triangle.
  const std::uint64_t mesh = v * (24 + 4 * a) + t * 12;
  const std::string ext = lower_ext(path);
  // The binary buffer: y-up positions and normals, attributes, 32-bit indices.
  const std::uint64_t bin = v * (24 + 4 * a) + t * 12;
  std::uint64_t writer = 0;
  if (ext == ".glb" || ext == ".gltf") {
    // write_gltf: the normals' copy, the turned positions and normals and the
    // indices (v 36, t 12), the buffer, and the file (GLB: the buffer again;
    // .gltf: its base64, the JSON holding it, and the file's copy of that).
    writer = v * 36 + t * 12 + bin + (ext == ".glb" ? bin : 3 * (bin * 4 / 3 + 4));
  } else if (ext == ".stl") {
    writer = 84 + t * 50;  // the whole file: 50 bytes a triangle
  } else if (ext == ".fbx") {
    // Assimp's aiMesh (v 24, a face's aiFace and index array) and its ASCII
    // FBX exporter's node tree (normals by polygon vertex as doubles): 100
    // bytes a triangle beside the text. The text (about 122 bytes a
    // triangle, `%f` numbers) is built in Assimp's StreamWriter, a vector
    // that doubles, then copied whole into the export blob: the text plus
    // 1-2 times it, 2.4 times it counted (within a fifth either way).
    // Measured with Assimp 5.2 on a 1024 x 1024 DEM: 788 MiB over the
    // program's own, where 500 bytes a triangle had counted 1.38 times that
    // (MemoryEstimate.MeshAsFbxAtSize).
    const std::uint64_t text = t * 122;
    writer = v * 36 + t * 100 + text * 12 / 5;
  }
  return mesh + writer;
}

void write_mesh(const Mesh& mesh, const fs::path& path) {
  const std::string ext = lower_ext(path);
  if (ext == ".ply") return write_ply(mesh, path);
  if (ext == ".obj") return write_obj(mesh, path);
  if (ext == ".glb" || ext == ".gltf") return write_gltf(mesh, path);
  if (ext == ".stl") return write_stl(mesh, path);
  if (ext == ".fbx") return write_fbx(mesh, path);
  throw Error("cannot write mesh '" + path.string() + "': unknown extension '" + ext +
              "'; use .glb, .gltf, .fbx, .stl, .obj or .ply");
}

}  // namespace drift::terrain
