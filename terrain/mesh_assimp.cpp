// Meshes through Assimp (Debian 12's libassimp 5.2): reading glTF/GLB, FBX, STL,
// DAE and the rest, and writing FBX. Every file Assimp opens goes through
// CheckedIOSystem, so the input rules of every other reader hold here too
// (terrain/input_path.h, issue 34 class 1): no device or FIFO is opened, no read
// is unbounded, memory is checked before the bytes are allocated.
#include <assimp/MemoryIOWrapper.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Exporter.hpp>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <fstream>
#include <memory>
#include <string>
#include <system_error>

#include "terrain/atomic_file.h"
#include "terrain/error.h"
#include "terrain/input_path.h"
#include "terrain/memory.h"
#include "terrain/mesh_io.h"

namespace drift::terrain {

namespace fs = std::filesystem;

namespace {

// Assimp's in-memory structures for a mesh file take several times its bytes
// (FBX's arrays are zlib-compressed; a glTF's indices become aiFace objects of
// 16 bytes plus a heap array each). Asked of the machine before any byte is read.
constexpr std::uint64_t kAssimpBytesPerFileByte = 16;

// Opens files for Assimp only after the input checks, reading each whole into
// memory (size known first, memory checked), and refuses writes. The main file
// and a .gltf's external buffers alike.
class CheckedIOSystem : public Assimp::IOSystem {
 public:
  explicit CheckedIOSystem(fs::path main) : main_(std::move(main)) {}

  bool Exists(const char* file) const override {
    std::error_code ec;
    return fs::is_regular_file(fs::path(file), ec);
  }
  char getOsSeparator() const override { return '/'; }

  Assimp::IOStream* Open(const char* file, const char* mode) override {
    const std::string m = mode ? mode : "r";
    if (m.find_first_of("wa+") != std::string::npos) return nullptr;
    const fs::path path(file);
    check_input_file(path, "mesh");
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec) throw Error("cannot read mesh '" + path.string() + "': " + ec.message());
    if (size == 0) return nullptr;  // Assimp reports an empty file as unreadable
    require_memory(kAssimpBytesPerFileByte * static_cast<std::uint64_t>(size),
                   "mesh '" + path.string() + "' (" + human_bytes(size) + ")",
                   "use a smaller mesh");
    std::unique_ptr<std::uint8_t[]> bytes(new std::uint8_t[size]);
    std::ifstream in(path, std::ios::binary);
    if (!in.read(reinterpret_cast<char*>(bytes.get()), static_cast<std::streamsize>(size))) {
      throw Error("cannot read mesh '" + path.string() + "' (it changed while being read?)");
    }
    // MemoryIOStream owns the bytes (delete[]) when `own` is true.
    return new Assimp::MemoryIOStream(bytes.release(), static_cast<std::size_t>(size), true);
  }

  void Close(Assimp::IOStream* stream) override { delete stream; }

 private:
  fs::path main_;
};

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// A scene metadata number (Assimp stores FBX's header fields as int32, float or double).
bool metadata_number(const aiScene& scene, const char* key, double& out) {
  if (!scene.mMetaData) return false;
  const aiMetadata& md = *scene.mMetaData;
  for (unsigned i = 0; i < md.mNumProperties; ++i) {
    if (std::string(md.mKeys[i].C_Str()) != key) continue;
    const aiMetadataEntry& e = md.mValues[i];
    switch (e.mType) {
      case AI_INT32:
        out = *static_cast<const std::int32_t*>(e.mData);
        return true;
      case AI_FLOAT:
        out = *static_cast<const float*>(e.mData);
        return true;
      case AI_DOUBLE:
        out = *static_cast<const double*>(e.mData);
        return true;
      default:
        return false;
    }
  }
  return false;
}

// The matrix from the file's frame (after units) to drift's (metres, z up).
// Rows: where drift's x, y and z are in the file's axes.
Eigen::Matrix3d file_to_drift(const aiScene& scene, const std::string& ext, UpAxis up,
                              const fs::path& path) {
  Eigen::Matrix3d yup;
  yup << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // (x, y, z) -> (x, -z, y)
  if (up == UpAxis::Z) return Eigen::Matrix3d::Identity();
  if (up == UpAxis::Y) return yup;
  // Auto. glTF is y up by its specification; Assimp turns DAE's <up_axis> into y up.
  if (ext == ".glb" || ext == ".gltf" || ext == ".dae" || ext == ".zae") return yup;
  if (ext == ".fbx") {
    // FBX's GlobalSettings: UpAxis/CoordAxis 0, 1, 2 for x, y, z, with signs.
    // drift's z is the file's up, drift's x its coord (right) axis, and y = z x x
    // keeps the frame right-handed (the file's front axis is implied).
    double up_axis = 1, up_sign = 1, coord_axis = 0, coord_sign = 1;
    metadata_number(scene, "UpAxis", up_axis);
    metadata_number(scene, "UpAxisSign", up_sign);
    metadata_number(scene, "CoordAxis", coord_axis);
    metadata_number(scene, "CoordAxisSign", coord_sign);
    const int u = static_cast<int>(up_axis), c = static_cast<int>(coord_axis);
    if (u < 0 || u > 2 || c < 0 || c > 2 || u == c) {
      throw Error("mesh '" + path.string() + "': its FBX header gives UpAxis " + std::to_string(u) +
                  " and CoordAxis " + std::to_string(c) +
                  "; re-export it, or set y_up to say which way is up");
    }
    Eigen::Vector3d x = Eigen::Vector3d::Zero(), z = Eigen::Vector3d::Zero();
    x[c] = coord_sign < 0 ? -1 : 1;
    z[u] = up_sign < 0 ? -1 : 1;
    Eigen::Matrix3d m;
    m.row(0) = x.transpose();
    m.row(1) = z.cross(x).transpose();
    m.row(2) = z.transpose();
    return m;
  }
  return Eigen::Matrix3d::Identity();  // STL, 3DS, ...: z up as stored
}

// Metres per unit of the file's coordinates.
double metres_per_unit(const aiScene& scene, const std::string& ext, const fs::path& path) {
  if (ext != ".fbx") return 1.0;
  double cm = 1.0;  // FBX's default unit is the centimetre
  metadata_number(scene, "UnitScaleFactor", cm);
  if (!(cm > 0) || !std::isfinite(cm)) {
    throw Error("mesh '" + path.string() + "': its FBX header's UnitScaleFactor is " +
                std::to_string(cm) + "; it must be a positive number of centimetres");
  }
  return cm / 100.0;
}

void append_node(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent,
                 const Eigen::Matrix3d& axes, double scale, Mesh& out, const fs::path& path) {
  const aiMatrix4x4 t = parent * node.mTransformation;
  aiMatrix3x3 normal_t(t);
  normal_t.Inverse().Transpose();
  for (unsigned k = 0; k < node.mNumMeshes; ++k) {
    const aiMesh& m = *scene.mMeshes[node.mMeshes[k]];
    if (!(m.mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;  // points, lines
    const int base = static_cast<int>(out.positions.size());
    const bool normals = m.HasNormals();
    for (unsigned v = 0; v < m.mNumVertices; ++v) {
      const aiVector3D p = t * m.mVertices[v];
      const Eigen::Vector3d q = axes * (scale * Eigen::Vector3d(p.x, p.y, p.z));
      if (!q.allFinite() || q.cwiseAbs().maxCoeff() > 1e30) {
        throw Error("mesh '" + path.string() + "': vertex " + std::to_string(v) + " of mesh '" +
                    m.mName.C_Str() + "' has a non-finite or huge coordinate");
      }
      out.positions.push_back(q.cast<float>());
      if (normals) {
        aiVector3D n = normal_t * m.mNormals[v];
        const Eigen::Vector3d d = axes * Eigen::Vector3d(n.x, n.y, n.z);
        out.normals.push_back(d.norm() > 0 ? Eigen::Vector3f(d.normalized().cast<float>())
                                           : Eigen::Vector3f(0, 0, 1));
      }
    }
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
      const aiFace& face = m.mFaces[f];
      if (face.mNumIndices != 3) continue;
      std::array<int, 3> tri{};
      for (int c = 0; c < 3; ++c) {
        if (face.mIndices[c] >= m.mNumVertices) {
          throw Error("mesh '" + path.string() + "': face " + std::to_string(f) + " names vertex " +
                      std::to_string(face.mIndices[c]) + " of " + std::to_string(m.mNumVertices));
        }
        tri[c] = base + static_cast<int>(face.mIndices[c]);
      }
      out.triangles.push_back(tri);
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c)
    append_node(scene, *node.mChildren[c], t, axes, scale, out, path);
}

}  // namespace

std::string mesh_read_extensions() {
  Assimp::Importer importer;
  std::string list;
  importer.GetExtensionList(list);
  return list;
}

Mesh read_mesh_assimp(const fs::path& path, UpAxis up) {
  check_input_file(path, "mesh");
  const std::string ext = lower_extension(path);
  Assimp::Importer importer;
  if (!importer.IsExtensionSupported(ext)) {
    throw Error("cannot read mesh '" + path.string() + "': Assimp reads no '" + ext +
                "' files; use glTF/GLB, FBX, STL, DAE, OBJ or PLY");
  }
  importer.SetIOHandler(new CheckedIOSystem(path));  // the importer owns it
  // Points and lines removed; everything else triangulated. No vertex joining, so
  // that a file drift wrote reads back vertex for vertex.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_SortByPType |
                                           aiProcess_ValidateDataStructure);
  if (!scene || !scene->mRootNode) {
    throw Error("cannot read mesh '" + path.string() + "': " + importer.GetErrorString() +
                " (is it a valid " + (ext.empty() ? std::string("mesh") : ext.substr(1)) +
                " file?)");
  }
  const Eigen::Matrix3d axes = file_to_drift(*scene, ext, up, path);
  const double scale = metres_per_unit(*scene, ext, path);
  Mesh mesh;
  append_node(*scene, *scene->mRootNode, aiMatrix4x4(), axes, scale, mesh, path);
  if (mesh.normals.size() != mesh.positions.size()) mesh.normals.clear();
  if (mesh.triangles.empty()) {
    throw Error("mesh '" + path.string() + "' has no triangles; export it with faces, not points");
  }
  return mesh;
}

void write_fbx(const Mesh& mesh, const fs::path& path) {
  if (mesh.triangles.empty()) throw Error("cannot write '" + path.string() + "': empty mesh");
  const std::vector<Eigen::Vector3f> normals =
      mesh.normals.size() == mesh.positions.size() ? mesh.normals : vertex_normals(mesh);
  // A scene of one mesh under the root, y up and in centimetres (FBX's unit).
  aiScene scene;
  scene.mRootNode = new aiNode("root");
  scene.mRootNode->mNumMeshes = 1;
  scene.mRootNode->mMeshes = new unsigned[1]{0};
  scene.mNumMaterials = 1;
  scene.mMaterials = new aiMaterial* [1] { new aiMaterial() };
  scene.mNumMeshes = 1;
  scene.mMeshes = new aiMesh* [1] { new aiMesh() };
  aiMesh& m = *scene.mMeshes[0];
  m.mName = path.stem().string();
  m.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  m.mMaterialIndex = 0;
  m.mNumVertices = static_cast<unsigned>(mesh.positions.size());
  m.mVertices = new aiVector3D[m.mNumVertices];
  m.mNormals = new aiVector3D[m.mNumVertices];
  for (unsigned v = 0; v < m.mNumVertices; ++v) {
    const Eigen::Vector3f& p = mesh.positions[v];
    const Eigen::Vector3f& n = normals[v];
    m.mVertices[v] = aiVector3D(100 * p.x(), 100 * p.z(), -100 * p.y());
    m.mNormals[v] = aiVector3D(n.x(), n.z(), -n.y());
  }
  m.mNumFaces = static_cast<unsigned>(mesh.triangles.size());
  m.mFaces = new aiFace[m.mNumFaces];
  for (unsigned f = 0; f < m.mNumFaces; ++f) {
    m.mFaces[f].mNumIndices = 3;
    m.mFaces[f].mIndices = new unsigned[3];
    for (int c = 0; c < 3; ++c)
      m.mFaces[f].mIndices[c] =
          static_cast<unsigned>(mesh.triangles[f][static_cast<std::size_t>(c)]);
  }
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(&scene, "fbxa");
  if (!blob) throw Error("cannot write '" + path.string() + "': " + exporter.GetErrorString());
  AtomicFile out(path);
  write_all_bytes(out.temp_path(), blob->data, blob->size, path);
  out.commit();
}

}  // namespace drift::terrain
