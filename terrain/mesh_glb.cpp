// Reading glTF binary (GLB) directly, for drift's named per-vertex attributes:
// Assimp 5.2 drops glTF's custom vertex attributes (assimp#4830), so a snowy
// objects file written as GLB (`drift snow fall --mesh-out x.glb`) lost its
// snow coverage through read_mesh. This reader takes the GLBs write_gltf
// writes, and any GLB of the same plain form: triangle primitives, float
// POSITION / NORMAL / custom SCALAR attributes, unsigned indices, buffer 0 the
// GLB's BIN chunk. Every length, offset and count is checked against the file
// before anything is sized by it (Khronos glTF 2.0, 4.4 GLB, 3.6 accessors,
// 3.7 meshes). The JSON chunk is parsed by GDAL's CPLJSONDocument (json-c,
// GDAL already a dependency; nesting depth limited).
#include <cpl_error.h>
#include <cpl_json.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "terrain/error.h"
#include "terrain/input_path.h"
#include "terrain/memory.h"
#include "terrain/mesh_io.h"

namespace drift::terrain {

namespace fs = std::filesystem;

namespace {

constexpr int kFloat = 5126, kUnsignedByte = 5121, kUnsignedShort = 5123, kUnsignedInt = 5125;
constexpr std::int64_t kMaxCount = std::int64_t{1} << 31;  // as read_ply: indices are int

std::uint32_t le32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}

// glTF's custom attribute "_SNOW_COVERAGE" -> drift's "snow_coverage" (the
// inverse of write_gltf's naming for names of letters, digits and '_').
std::string attribute_name(const std::string& gltf) {
  std::string out;
  for (std::size_t i = 1; i < gltf.size(); ++i)
    out += static_cast<char>(std::tolower(static_cast<unsigned char>(gltf[i])));
  return out;
}

class GlbReader {
 public:
  GlbReader(const fs::path& path, const std::vector<std::uint8_t>& file)
      : path_(path), file_(file) {}

  Mesh read() {
    chunks();
    parse_json();
    Mesh mesh;
    origin(mesh);
    check_nodes();
    const CPLJSONArray meshes = array(json_root_, "meshes", "the file");
    if (meshes.Size() == 0) throw bad("it holds no meshes");
    for (int m = 0; m < meshes.Size(); ++m) {
      const CPLJSONArray prims = array(meshes[m], "primitives", "mesh " + std::to_string(m));
      for (int p = 0; p < prims.Size(); ++p)
        primitive(prims[p], "mesh " + std::to_string(m) + " primitive " + std::to_string(p), mesh);
    }
    if (mesh.triangles.empty()) throw bad("it holds no triangles");
    return mesh;
  }

 private:
  Error bad(const std::string& what) const {
    return Error("cannot read mesh '" + path_.string() + "': " + what +
                 " (drift reads GLB files of the form drift writes; convert others to PLY or "
                 "OBJ)");
  }

  // The 12-byte header, the JSON chunk and the BIN chunk (4.4.2, 4.4.3).
  void chunks() {
    const std::size_t size = file_.size();
    if (size < 20) throw bad("the file is " + std::to_string(size) + " bytes, too short for GLB");
    if (le32(file_.data()) != 0x46546C67) throw bad("no 'glTF' magic at its start");
    if (le32(file_.data() + 4) != 2)
      throw bad("GLB version " + std::to_string(le32(file_.data() + 4)) + ", not 2");
    if (le32(file_.data() + 8) != size) {
      throw bad("its header gives a length of " + std::to_string(le32(file_.data() + 8)) +
                " bytes but the file has " + std::to_string(size) + " (truncated?)");
    }
    std::size_t at = 12;
    for (int k = 0; at < size; ++k) {
      if (size - at < 8) throw bad("chunk " + std::to_string(k) + "'s header is cut off");
      const std::uint64_t length = le32(file_.data() + at), type = le32(file_.data() + at + 4);
      if (length > size - at - 8) {
        throw bad("chunk " + std::to_string(k) + " declares " + std::to_string(length) +
                  " bytes at offset " + std::to_string(at + 8) + ", past the file's end (" +
                  std::to_string(size) + " bytes)");
      }
      const std::uint8_t* data = file_.data() + at + 8;
      if (k == 0 && type != 0x4E4F534A) throw bad("its first chunk is not JSON");
      if (k == 0) json_ = {data, static_cast<std::size_t>(length)};
      if (k == 1 && type == 0x004E4942) bin_ = {data, static_cast<std::size_t>(length)};
      at += 8 + length;
    }
  }

  void parse_json() {
    if (json_.size > static_cast<std::size_t>(std::numeric_limits<int>::max()))
      throw bad("its JSON chunk is larger than 2 GB");
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
    const bool ok = json_doc_.LoadMemory(json_.data, static_cast<int>(json_.size));
    const std::string reason = CPLGetLastErrorMsg();
    CPLPopErrorHandler();
    if (!ok) throw bad("its JSON chunk does not parse: " + reason);
    json_ = {};
    json_root_ = json_doc_.GetRoot();
    if (json_root_.GetType() != CPLJSONObject::Type::Object)
      throw bad("its JSON chunk is not an object");
    if (json_root_.GetObj("extensionsRequired").IsValid())
      throw bad("it requires extensions (extensionsRequired), which drift does not read");
  }

  // A member that must be an array.
  CPLJSONArray array(const CPLJSONObject& o, const char* key, const std::string& where) const {
    const CPLJSONObject v = o.GetObj(key);
    if (!v.IsValid() || v.GetType() != CPLJSONObject::Type::Array)
      throw bad(where + " has no array '" + key + "'");
    return v.ToArray();
  }

  // An integer member in [lo, hi]; `fallback` when absent (none: required).
  std::int64_t integer(const CPLJSONObject& o, const char* key, const std::string& where,
                       std::int64_t lo, std::int64_t hi, std::int64_t fallback = -1,
                       bool required = true) const {
    const CPLJSONObject v = o.GetObj(key);
    if (!v.IsValid()) {
      if (required) throw bad(where + " has no '" + key + "'");
      return fallback;
    }
    return integer_value(v, where + "'s '" + key + "'", lo, hi);
  }

  std::int64_t integer_value(const CPLJSONObject& v, const std::string& what, std::int64_t lo,
                             std::int64_t hi) const {
    const auto type = v.GetType();
    if (type != CPLJSONObject::Type::Integer && type != CPLJSONObject::Type::Long)
      throw bad(what + " is not an integer");
    const std::int64_t n = v.ToLong();
    if (n < lo || n > hi) {
      throw bad(what + " is " + std::to_string(n) + ", outside [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "]");
    }
    return n;
  }

  void origin(Mesh& mesh) const {
    const CPLJSONObject o = json_root_.GetObj("asset").GetObj("extras").GetObj("drift_origin");
    if (!o.IsValid()) return;  // another writer's GLB: no CRS origin
    const CPLJSONArray a = o.ToArray();
    bool ok = o.GetType() == CPLJSONObject::Type::Array && a.Size() == 3;
    for (int k = 0; ok && k < 3; ++k) {
      const auto t = a[k].GetType();
      ok = (t == CPLJSONObject::Type::Double || t == CPLJSONObject::Type::Integer ||
            t == CPLJSONObject::Type::Long) &&
           std::isfinite(a[k].ToDouble());
      if (ok) mesh.origin[k] = a[k].ToDouble();
    }
    if (!ok) throw bad("asset.extras.drift_origin is not three finite numbers");
  }

  // drift writes one node with no transform; a node's transform is not applied here.
  void check_nodes() const {
    const CPLJSONObject nodes = json_root_.GetObj("nodes");
    if (!nodes.IsValid()) return;
    const CPLJSONArray a = nodes.ToArray();
    for (int n = 0; n < a.Size(); ++n) {
      for (const char* key : {"matrix", "translation", "rotation", "scale"})
        if (a[n].GetObj(key).IsValid())
          throw bad("node " + std::to_string(n) + " has a '" + key + "', which is not applied");
    }
  }

  struct Span {
    const std::uint8_t* data = nullptr;
    std::size_t size = 0;
  };

  // Accessor `index`'s bytes, checked: its type and component type among
  // those asked, its count, offset and stride inside its bufferView, the view
  // inside buffer 0, buffer 0 the BIN chunk.
  Span accessor(std::int64_t index, const char* type, std::initializer_list<int> components,
                int& component, std::size_t& count, const std::string& what) const {
    const CPLJSONArray accessors = array(json_root_, "accessors", "the file");
    if (index < 0 || index >= accessors.Size()) {
      throw bad(what + " names accessor " + std::to_string(index) + " of " +
                std::to_string(accessors.Size()));
    }
    const CPLJSONObject acc = accessors[static_cast<int>(index)];
    const std::string where = "accessor " + std::to_string(index) + " (" + what + ")";
    if (acc.GetObj("sparse").IsValid()) throw bad(where + " is sparse, which drift does not read");
    component = static_cast<int>(integer(acc, "componentType", where, 5120, 5126));
    if (std::find(components.begin(), components.end(), component) == components.end())
      throw bad(where + " has componentType " + std::to_string(component) +
                ", not one drift reads");
    if (acc.GetString("type") != type)
      throw bad(where + " is of type '" + acc.GetString("type") + "', not " + type);
    if (acc.GetBool("normalized", false)) throw bad(where + " is normalized");
    const int comps = std::string(type) == "VEC3" ? 3 : 1;
    const std::size_t element =
        static_cast<std::size_t>(comps) * (component == kUnsignedByte    ? 1
                                           : component == kUnsignedShort ? 2
                                                                         : 4);
    const auto n = integer(acc, "count", where, 1, kMaxCount);
    const auto acc_offset = integer(acc, "byteOffset", where, 0, kMaxCount * 16, 0, false);
    const auto view_index = integer(acc, "bufferView", where, 0, kMaxCount);
    const CPLJSONArray views = array(json_root_, "bufferViews", "the file");
    if (view_index >= views.Size()) {
      throw bad(where + " names bufferView " + std::to_string(view_index) + " of " +
                std::to_string(views.Size()));
    }
    const CPLJSONObject view = views[static_cast<int>(view_index)];
    const std::string vwhere = "bufferView " + std::to_string(view_index);
    if (integer(view, "buffer", vwhere, 0, kMaxCount) != 0)
      throw bad(vwhere + " is not in buffer 0, the GLB's BIN chunk");
    const std::int64_t limit = static_cast<std::int64_t>(file_.size());
    const auto view_offset = integer(view, "byteOffset", vwhere, 0, limit, 0, false);
    const auto view_length = integer(view, "byteLength", vwhere, 1, limit);
    const auto stride = integer(view, "byteStride", vwhere, 4, 252, 0, false);
    if (stride != 0 && static_cast<std::size_t>(stride) != element) {
      throw bad(vwhere + " interleaves (byteStride " + std::to_string(stride) + " for " +
                std::to_string(element) + "-byte elements), which drift does not read");
    }
    const CPLJSONArray buffers = array(json_root_, "buffers", "the file");
    if (buffers.Size() < 1) throw bad("it declares no buffer");
    if (buffers[0].GetObj("uri").IsValid()) throw bad("buffer 0 names a uri, not the BIN chunk");
    const auto buffer_length = integer(buffers[0], "byteLength", "buffer 0", 1, limit);
    if (!bin_.data) throw bad("it has no BIN chunk");
    if (static_cast<std::size_t>(buffer_length) > bin_.size) {
      throw bad("buffer 0 declares " + std::to_string(buffer_length) +
                " bytes but the BIN chunk holds " + std::to_string(bin_.size));
    }
    if (view_offset + view_length > buffer_length) {
      throw bad(vwhere + " (" + std::to_string(view_length) + " bytes at offset " +
                std::to_string(view_offset) + ") reaches past buffer 0's " +
                std::to_string(buffer_length) + " bytes");
    }
    // count * element, compared without overflow: count <= 2^31, element <= 12.
    const std::int64_t bytes = n * static_cast<std::int64_t>(element);
    if (acc_offset > view_length || bytes > view_length - acc_offset) {
      throw bad(where + " declares " + std::to_string(n) + " elements of " +
                std::to_string(element) + " bytes at offset " + std::to_string(acc_offset) +
                ", past its bufferView's " + std::to_string(view_length) + " bytes");
    }
    if ((view_offset + acc_offset) % static_cast<std::int64_t>(element / comps) != 0)
      throw bad(where + " is not aligned to its component size");
    count = static_cast<std::size_t>(n);
    return {bin_.data + view_offset + acc_offset, static_cast<std::size_t>(bytes)};
  }

  std::vector<float> floats(std::int64_t index, const char* type, std::size_t& count,
                            const std::string& what) const {
    int component = 0;
    const Span s = accessor(index, type, {kFloat}, component, count, what);
    std::vector<float> out(s.size / 4);
    std::memcpy(out.data(), s.data, s.size);  // little-endian hosts only, as the PLY reader
    return out;
  }

  void primitive(const CPLJSONObject& prim, const std::string& where, Mesh& mesh) const {
    if (integer(prim, "mode", where, 0, 6, 4, false) != 4)
      throw bad(where + " is not of triangles (mode 4)");
    const CPLJSONObject attrs = prim.GetObj("attributes");
    if (!attrs.IsValid() || attrs.GetType() != CPLJSONObject::Type::Object)
      throw bad(where + " has no attributes");
    const std::int64_t ipos = integer(attrs, "POSITION", where + " attributes", 0, kMaxCount);
    std::size_t n = 0;
    const std::vector<float> pos = floats(ipos, "VEC3", n, where + " POSITION");
    if (static_cast<std::uint64_t>(mesh.positions.size()) + n >
        static_cast<std::uint64_t>(kMaxCount))
      throw bad("it holds more than 2^31 vertices");
    const std::size_t base = mesh.positions.size();
    // glTF's y up back into drift's z up: (x, y, z) -> (x, -z, y), write_gltf's inverse.
    for (std::size_t v = 0; v < n; ++v) {
      const Eigen::Vector3f p(pos[3 * v], -pos[3 * v + 2], pos[3 * v + 1]);
      if (!p.allFinite()) throw bad(where + " vertex " + std::to_string(v) + " is not finite");
      mesh.positions.push_back(p);
    }
    std::vector<std::pair<std::string, std::vector<float>>> custom;
    std::vector<float> nor;
    for (const CPLJSONObject& a : attrs.GetChildren()) {
      const std::string name = a.GetName();
      const bool normal = name == "NORMAL";
      if (!normal && !(name.size() > 1 && name[0] == '_')) continue;  // TEXCOORD_0, COLOR_0, ...
      const std::string what = std::string(where).append(" ").append(name);
      std::size_t c = 0;
      std::vector<float> values =
          floats(integer_value(a, what, 0, kMaxCount), normal ? "VEC3" : "SCALAR", c, what);
      if (c != n) {
        throw bad(what + " has " + std::to_string(c) + " values for " + std::to_string(n) +
                  " vertices");
      }
      if (normal)
        nor = std::move(values);
      else
        custom.emplace_back(attribute_name(name), std::move(values));
    }
    // Normals only if every primitive has them.
    if (!nor.empty() && mesh.normals.size() == base) {
      for (std::size_t v = 0; v < n; ++v)
        mesh.normals.emplace_back(nor[3 * v], -nor[3 * v + 2], nor[3 * v + 1]);
    } else {
      mesh.normals.clear();
    }
    merge_attributes(custom, base, n, where, mesh);
    indices(prim, where, base, n, mesh);
  }

  // Every primitive must carry the same custom attributes (a mesh's attribute
  // covers all its vertices).
  void merge_attributes(std::vector<std::pair<std::string, std::vector<float>>>& custom,
                        std::size_t base, std::size_t n, const std::string& where,
                        Mesh& mesh) const {
    if (base == 0) {
      mesh.vertex_attributes = std::move(custom);
      return;
    }
    if (custom.size() != mesh.vertex_attributes.size())
      throw bad(where + " has other custom attributes than the first primitive");
    for (auto& attribute : mesh.vertex_attributes) {
      const std::string& name = attribute.first;  // captured below: no structured binding
      std::vector<float>& values = attribute.second;
      auto it = std::find_if(custom.begin(), custom.end(),
                             [&](const auto& c) { return c.first == name; });
      if (it == custom.end())
        throw bad(std::string(where).append(" has no attribute '").append(name).append("'"));
      values.insert(values.end(), it->second.begin(), it->second.begin() + static_cast<long>(n));
    }
  }

  void indices(const CPLJSONObject& prim, const std::string& where, std::size_t base, std::size_t n,
               Mesh& mesh) const {
    std::vector<std::uint32_t> idx;
    if (prim.GetObj("indices").IsValid()) {
      int component = 0;
      std::size_t count = 0;
      const Span s = accessor(integer(prim, "indices", where, 0, kMaxCount), "SCALAR",
                              {kUnsignedByte, kUnsignedShort, kUnsignedInt}, component, count,
                              where + " indices");
      idx.resize(count);
      for (std::size_t i = 0; i < count; ++i) {
        const std::uint8_t* p = s.data + i * (s.size / count);
        idx[i] = component == kUnsignedByte    ? p[0]
                 : component == kUnsignedShort ? static_cast<std::uint32_t>(p[0] | p[1] << 8)
                                               : le32(p);
      }
    } else {
      idx.resize(n);
      for (std::size_t i = 0; i < n; ++i) idx[i] = static_cast<std::uint32_t>(i);
    }
    if (idx.size() % 3 != 0) {
      throw bad(where + " has " + std::to_string(idx.size()) +
                " indices, not a whole number of triangles");
    }
    for (std::size_t t = 0; t < idx.size(); t += 3) {
      std::array<int, 3> tri{};
      for (int k = 0; k < 3; ++k) {
        if (idx[t + static_cast<std::size_t>(k)] >= n) {
          throw bad(where + " triangle " + std::to_string(t / 3) + " names vertex " +
                    std::to_string(idx[t + static_cast<std::size_t>(k)]) + " of " +
                    std::to_string(n));
        }
        tri[static_cast<std::size_t>(k)] =
            static_cast<int>(base + idx[t + static_cast<std::size_t>(k)]);
      }
      mesh.triangles.push_back(tri);
    }
  }

  const fs::path& path_;
  const std::vector<std::uint8_t>& file_;
  Span json_, bin_;
  CPLJSONDocument json_doc_;
  CPLJSONObject json_root_;
};

}  // namespace

Mesh read_glb(const fs::path& path) {
  check_input_file(path, "mesh");
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw Error("cannot read mesh '" + path.string() + "': " + ec.message());
  if (size > std::numeric_limits<std::uint32_t>::max())
    throw Error("cannot read mesh '" + path.string() + "': larger than GLB's 4 GB limit");
  // The file, json-c's tree of the JSON chunk (a few times its bytes) and
  // the mesh (positions, normals, attributes, triangles: at most about the
  // BIN chunk's bytes twice over).
  require_memory(4 * static_cast<std::uint64_t>(size),
                 "mesh '" + path.string() + "' (" + std::to_string(size) + " bytes)",
                 "use a smaller mesh");
  std::vector<std::uint8_t> file(static_cast<std::size_t>(size));
  std::ifstream in(path, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(file.data()), static_cast<std::streamsize>(size)))
    throw Error("cannot read mesh '" + path.string() + "' (it changed while being read?)");
  return GlbReader(path, file).read();
}

}  // namespace drift::terrain
