// Writing glTF 2.0 (GLB and .gltf) and binary STL by hand: both are a few
// fixed-layout blocks, and writing them here keeps drift's named per-vertex
// attributes (glTF custom attributes "_NAME", which Assimp's exporter has no
// place for) and the origin in the CRS. Specification: Khronos glTF 2.0,
// sections 3.7 (meshes, attribute names), 3.6 (accessors, min/max), 4.4 (GLB).
#include <Eigen/Geometry>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "terrain/atomic_file.h"
#include "terrain/error.h"
#include "terrain/json_text.h"
#include "terrain/mesh_io.h"

namespace drift::terrain {

namespace fs = std::filesystem;

namespace {

// drift's z-up frame into glTF's y-up one: (x, y, z) -> (x, z, -y), a rotation
// about x by -90 degrees (determinant 1), so windings and normals keep their sense.
Eigen::Vector3f to_y_up(const Eigen::Vector3f& v) { return {v.x(), v.z(), -v.y()}; }

// Floats with 9 digits, the origin's doubles with 17 (terrain/json_text.h).
std::string number(double v) { return json_number(v, 9); }
std::string number17(double v) { return json_number(v); }

// "snow_coverage" -> "_SNOW_COVERAGE": glTF requires application-specific
// attribute names to start with an underscore (spec 3.7.2.1).
std::string custom_attribute_name(const std::string& name) {
  std::string out = "_";
  for (char c : name) {
    const unsigned char u = static_cast<unsigned char>(c);
    out += std::isalnum(u) ? static_cast<char>(std::toupper(u)) : '_';
  }
  return out;
}

// The binary buffer and the JSON's bufferViews and accessors, built together.
struct GltfBuffers {
  std::vector<std::uint8_t> bin;
  std::string views, accessors;
  int count = 0;

  // Appends `bytes` as a buffer view (4-byte aligned) and an accessor over it;
  // returns the accessor's index.
  int add(const void* bytes, std::size_t size, int component, const char* type, std::size_t n,
          int target, const std::string& minmax) {
    while (bin.size() % 4) bin.push_back(0);
    const std::size_t offset = bin.size();
    bin.resize(offset + size);
    std::memcpy(bin.data() + offset, bytes, size);
    if (count) {
      views += ",";
      accessors += ",";
    }
    views += "{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) +
             ",\"byteLength\":" + std::to_string(size) + ",\"target\":" + std::to_string(target) +
             "}";
    accessors += "{\"bufferView\":" + std::to_string(count) +
                 ",\"componentType\":" + std::to_string(component) +
                 ",\"count\":" + std::to_string(n) + ",\"type\":\"" + type + "\"" + minmax + "}";
    return count++;
  }
};

std::string base64(const std::vector<std::uint8_t>& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t a = bytes[i], b = i + 1 < bytes.size() ? bytes[i + 1] : 0,
                        c = i + 2 < bytes.size() ? bytes[i + 2] : 0;
    const std::uint32_t w = (a << 16) | (b << 8) | c;
    out += table[(w >> 18) & 63];
    out += table[(w >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(w >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[w & 63] : '=';
  }
  return out;
}

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

void check_writable_mesh(const Mesh& mesh, const fs::path& path) {
  if (mesh.triangles.empty()) throw Error("cannot write '" + path.string() + "': empty mesh");
  for (const auto& [name, values] : mesh.vertex_attributes) {
    if (values.size() != mesh.positions.size()) {
      throw Error("internal: attribute '" + name + "' has the wrong length for '" + path.string() +
                  "'");
    }
  }
}

}  // namespace

std::vector<Eigen::Vector3f> vertex_normals(const Mesh& mesh) {
  std::vector<Eigen::Vector3f> n(mesh.positions.size(), Eigen::Vector3f::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.positions[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3f& b = mesh.positions[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3f& c = mesh.positions[static_cast<std::size_t>(t[2])];
    const Eigen::Vector3f area2 = (b - a).cross(c - a);  // twice the area, along the normal
    for (int v : t) n[static_cast<std::size_t>(v)] += area2;
  }
  for (auto& v : n) v = v.norm() > 0 ? Eigen::Vector3f(v.normalized()) : Eigen::Vector3f(0, 0, 1);
  return n;
}

void write_gltf(const Mesh& mesh, const fs::path& path) {
  check_writable_mesh(mesh, path);
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool binary = ext != ".gltf";
  const std::size_t n = mesh.positions.size();
  const std::vector<Eigen::Vector3f> normals =
      mesh.normals.size() == n ? mesh.normals : vertex_normals(mesh);

  std::vector<float> positions(3 * n), normal_values(3 * n);
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (std::size_t v = 0; v < n; ++v) {
    const Eigen::Vector3f p = to_y_up(mesh.positions[v]);
    Eigen::Vector3f d = to_y_up(normals[v]);
    d = d.norm() > 0 ? Eigen::Vector3f(d.normalized())
                     : Eigen::Vector3f(0, 1, 0);  // unit (3.7.2.1)
    for (int k = 0; k < 3; ++k) {
      positions[3 * v + static_cast<std::size_t>(k)] = p[k];
      normal_values[3 * v + static_cast<std::size_t>(k)] = d[k];
    }
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::vector<std::uint32_t> indices;
  indices.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    for (int v : t) indices.push_back(static_cast<std::uint32_t>(v));

  constexpr int kFloat = 5126, kUnsignedInt = 5125, kArrayBuffer = 34962, kElementArray = 34963;
  GltfBuffers b;
  // POSITION's min and max are required (3.6.2.5); %.9g gives the floats exactly.
  const std::string bounds = ",\"min\":[" + number(lo.x()) + "," + number(lo.y()) + "," +
                             number(lo.z()) + "],\"max\":[" + number(hi.x()) + "," +
                             number(hi.y()) + "," + number(hi.z()) + "]";
  const int pos =
      b.add(positions.data(), positions.size() * 4, kFloat, "VEC3", n, kArrayBuffer, bounds);
  const int nor =
      b.add(normal_values.data(), normal_values.size() * 4, kFloat, "VEC3", n, kArrayBuffer, "");
  std::string attributes =
      "\"POSITION\":" + std::to_string(pos) + ",\"NORMAL\":" + std::to_string(nor);
  for (const auto& [name, values] : mesh.vertex_attributes) {
    const int a = b.add(values.data(), values.size() * 4, kFloat, "SCALAR", n, kArrayBuffer, "");
    attributes += ",\"" + custom_attribute_name(name) + "\":" + std::to_string(a);
  }
  const int idx = b.add(indices.data(), indices.size() * 4, kUnsignedInt, "SCALAR", indices.size(),
                        kElementArray, "");
  while (b.bin.size() % 4) b.bin.push_back(0);

  const std::string origin = "[" + number17(mesh.origin.x()) + "," + number17(mesh.origin.y()) +
                             "," + number17(mesh.origin.z()) + "]";
  std::string buffer = "{\"byteLength\":" + std::to_string(b.bin.size());
  if (!binary) buffer += ",\"uri\":\"data:application/octet-stream;base64," + base64(b.bin) + "\"";
  buffer += "}";
  const std::string name = path.stem().string();
  std::string json =
      "{\"asset\":{\"version\":\"2.0\",\"generator\":\"Driftscape\",\"extras\":{"
      "\"drift_origin\":" +
      origin +
      ",\"drift_note\":\"positions in metres, y up, relative to "
      "drift_origin (x east, y north, z up in the CRS)\"}},"
      "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
      "\"nodes\":[{\"mesh\":0,\"name\":\"" +
      custom_attribute_name(name).substr(1) +
      "\"}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{" +
      attributes + "},\"indices\":" + std::to_string(idx) +
      ",\"mode\":4}]}],"
      "\"buffers\":[" +
      buffer + "],\"bufferViews\":[" + b.views + "],\"accessors\":[" + b.accessors + "]}";

  std::vector<std::uint8_t> file;
  if (binary) {
    while (json.size() % 4) json += ' ';  // the JSON chunk is padded with spaces (4.4.3.1)
    file.reserve(28 + json.size() + b.bin.size());
    put_u32(file, 0x46546C67);  // "glTF"
    put_u32(file, 2);
    put_u32(file, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + b.bin.size()));
    put_u32(file, static_cast<std::uint32_t>(json.size()));
    put_u32(file, 0x4E4F534A);  // "JSON"
    file.insert(file.end(), json.begin(), json.end());
    put_u32(file, static_cast<std::uint32_t>(b.bin.size()));
    put_u32(file, 0x004E4942);  // "BIN"
    file.insert(file.end(), b.bin.begin(), b.bin.end());
  } else {
    file.assign(json.begin(), json.end());
  }
  AtomicFile out(path);
  write_all_bytes(out.temp_path(), file.data(), file.size(), path);
  out.commit();
}

void write_stl(const Mesh& mesh, const fs::path& path) {
  check_writable_mesh(mesh, path);
  std::vector<std::uint8_t> file(80, 0);
  file.reserve(84 + 50 * mesh.triangles.size());  // whole: growing by doubling held up to 2x
  const char header[] = "binary STL written by Driftscape: metres, z up";
  std::memcpy(file.data(), header, sizeof header - 1);
  put_u32(file, static_cast<std::uint32_t>(mesh.triangles.size()));
  auto put_vec = [&file](const Eigen::Vector3f& v) {
    for (int k = 0; k < 3; ++k) {
      std::uint32_t bits;
      std::memcpy(&bits, &v[k], 4);
      put_u32(file, bits);
    }
  };
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.positions[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3f& b = mesh.positions[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3f& c = mesh.positions[static_cast<std::size_t>(t[2])];
    const Eigen::Vector3f nrm = (b - a).cross(c - a);
    put_vec(nrm.norm() > 0 ? Eigen::Vector3f(nrm.normalized()) : Eigen::Vector3f(0, 0, 1));
    put_vec(a);
    put_vec(b);
    put_vec(c);
    file.push_back(0);
    file.push_back(0);
  }
  AtomicFile out(path);
  write_all_bytes(out.temp_path(), file.data(), file.size(), path);
  out.commit();
}

}  // namespace drift::terrain
