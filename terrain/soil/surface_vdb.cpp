// The one file that includes OpenVDB (a heavy header: docs/architecture.md,
// Debian 12 packages).
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>

#include "terrain/atomic_file.h"
#include "terrain/error.h"
#include "terrain/soil/soil_surface.h"

namespace drift::soil {

namespace {

void init_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// A sparse grid of `field` * sign (zeros stay background), index space =
// voxel indices, values at voxel centres.
openvdb::FloatGrid::Ptr to_grid(const terrain::Grid3Shape& g, const std::vector<float>& field,
                                float sign) {
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  auto acc = grid->getAccessor();
  for (int y = 0; y < g.ny; ++y)
    for (int x = 0; x < g.nx; ++x)
      for (int z = 0; z < g.nz; ++z) {
        const float v = field[g.index(x, y, z)];
        if (v != 0.0f) acc.setValue(openvdb::Coord(x, y, z), sign * v);
      }
  return grid;
}

using Leaf = openvdb::FloatTree::LeafNodeType;

// One leaf of the surface's grid: the values of to_grid(field, -1) in the
// leaf's 8^3 block, with only the voxels that have a face neighbour across
// the iso-value (density 0.5) active; null if the block holds no density.
// volumeToMesh takes every grid edge whose ends lie on both sides of the
// iso-value and one of which is active (evalInternalVoxelEdges,
// tools/VolumeToMesh.h); both ends of such an edge have a neighbour across,
// so the edges, and with the same values the mesh, are those of the fully
// active grid, while the soil's interior is skipped (issue 33, item 8;
// SoilSurface.BandGridGivesTheFullGridsMesh). A leaf reads the field in its
// block and one voxel around it, no further: what IsoMesher's incremental
// update relies on.
std::unique_ptr<Leaf> band_leaf(const terrain::Grid3Shape& g, const std::vector<float>& field,
                                int X, int Y, int Z) {
  auto inside = [&](int x, int y, int z) {
    return x >= 0 && y >= 0 && z >= 0 && x < g.nx && y < g.ny && z < g.nz &&
           field[g.index(x, y, z)] > 0.5f;
  };
  constexpr int D = Leaf::DIM;
  std::unique_ptr<Leaf> leaf;
  for (int x = X; x < std::min(g.nx, X + D); ++x)
    for (int y = Y; y < std::min(g.ny, Y + D); ++y)
      for (int z = Z; z < std::min(g.nz, Z + D); ++z) {
        const float v = field[g.index(x, y, z)];
        if (v == 0.0f) continue;
        if (!leaf) leaf = std::make_unique<Leaf>(openvdb::Coord(X, Y, Z), 0.0f, false);
        const openvdb::Coord c(x, y, z);
        leaf->setValueOnly(c, -v);
        const bool in = v > 0.5f;
        if (inside(x - 1, y, z) != in || inside(x + 1, y, z) != in || inside(x, y - 1, z) != in ||
            inside(x, y + 1, z) != in || inside(x, y, z - 1) != in || inside(x, y, z + 1) != in)
          leaf->setValueOn(c);
      }
  return leaf;
}

// OpenVDB's header (io/Archive.cc, writeHeader): magic (8 bytes), file
// version, library major and minor (4 each), the grid-offsets flag (1), then
// the archive's UUID as 36 ASCII characters.
constexpr std::size_t kUuidOffset = 21, kUuidLength = 36;

// OpenVDB stamps every file with a random UUID (boost's random_generator), so
// two identical runs wrote different bytes. The UUID only lets readers tell
// files apart; replace it by one derived from the rest of the file (FNV-1a,
// formatted as a UUID), so the same grids give the same bytes.
void stamp_content_uuid(std::string& bytes, const std::string& shown) {
  if (bytes.size() < kUuidOffset + kUuidLength || bytes[kUuidOffset + 8] != '-')
    throw Error("'" + shown + "': unexpected OpenVDB header (no UUID at byte 21)");
  std::uint64_t h[2] = {1469598103934665603ull, 1099511628211ull * 31};
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i >= kUuidOffset && i < kUuidOffset + kUuidLength) continue;
    for (std::uint64_t& x : h) x = (x ^ static_cast<unsigned char>(bytes[i])) * 1099511628211ull;
  }
  char uuid[kUuidLength + 1];
  std::snprintf(uuid, sizeof uuid, "%08x-%04x-%04x-%04x-%012llx", static_cast<unsigned>(h[0] >> 32),
                static_cast<unsigned>((h[0] >> 16) & 0xffff),
                static_cast<unsigned>(0x5000 | (h[0] & 0x0fff)),  // version 5 style: name-based
                static_cast<unsigned>(0x8000 | ((h[1] >> 48) & 0x3fff)),
                static_cast<unsigned long long>(h[1] & 0xffffffffffffull));
  bytes.replace(kUuidOffset, kUuidLength, uuid, kUuidLength);
}

// OpenVDB's archive written into memory with the layout io::File writes
// (seekable: grid offsets in the file, so readers can load one grid):
// io::File writes through an std::ofstream whose failed writes on a full disk
// it never checks, which left a truncated VDB behind with exit 0. In memory,
// every byte then goes through write_all_bytes, which checks each write
// (issue 34).
class MemoryArchive : public openvdb::io::Archive {
 public:
  std::string encode(const openvdb::GridPtrVec& grids) const {
    std::ostringstream os(std::ios_base::out | std::ios_base::binary);
    Archive::write(os, grids, /*seekable=*/true);
    if (!os) throw Error("OpenVDB could not encode the grids");
    return std::move(os).str();
  }
};

// The mesh of `grid` (a negated field: "inside" is below the iso-value, as
// for a level set, so volumeToMesh orients faces outwards; the background (0)
// is outside) in metres.
terrain::Mesh grid_mesh(const terrain::Grid3Shape& g, const openvdb::FloatGrid& grid) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, triangles, quads, -0.5, 0.0);
  terrain::Mesh mesh;
  mesh.positions.reserve(points.size());
  const double h = g.voxel_size;
  for (const auto& p : points)
    mesh.positions.push_back(
        (g.origin + h * Eigen::Vector3d(p.x() + 0.5, p.y() + 0.5, p.z() + 0.5)).cast<float>());
  mesh.triangles.reserve(triangles.size() + 2 * quads.size());
  // With the negated field OpenVDB's faces are counter-clockwise seen from
  // outside, as ours (tested: the enclosed volume comes out positive).
  for (const auto& t : triangles)
    mesh.triangles.push_back(
        {static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2])});
  for (const auto& q : quads) {
    mesh.triangles.push_back(
        {static_cast<int>(q[0]), static_cast<int>(q[1]), static_cast<int>(q[2])});
    mesh.triangles.push_back(
        {static_cast<int>(q[0]), static_cast<int>(q[2]), static_cast<int>(q[3])});
  }
  return mesh;
}

}  // namespace

struct IsoMesher::Impl {
  terrain::Grid3Shape shape;
  int bx = 0, by = 0, bz = 0;                 // leaves a side
  std::vector<std::unique_ptr<Leaf>> leaves;  // x fastest, then y, then z
};

IsoMesher::IsoMesher() : impl_(std::make_unique<Impl>()) {}
IsoMesher::~IsoMesher() = default;
IsoMesher::IsoMesher(IsoMesher&&) noexcept = default;
IsoMesher& IsoMesher::operator=(IsoMesher&&) noexcept = default;

std::size_t IsoMesher::update(const terrain::Grid3Shape& g, const std::vector<float>& field,
                              const std::vector<unsigned char>* dirty) {
  Impl& m = *impl_;
  const bool same = g.nx == m.shape.nx && g.ny == m.shape.ny && g.nz == m.shape.nz &&
                    g.voxel_size == m.shape.voxel_size && g.origin == m.shape.origin;
  if (!same) {
    m.shape = g;
    m.bx = (g.nx + kLeaf - 1) / kLeaf;
    m.by = (g.ny + kLeaf - 1) / kLeaf;
    m.bz = (g.nz + kLeaf - 1) / kLeaf;
    m.leaves.clear();
    m.leaves.resize(static_cast<std::size_t>(m.bx) * m.by * m.bz);
    dirty = nullptr;
  }
  std::vector<int> todo;
  for (std::size_t b = 0; b < m.leaves.size(); ++b)
    if (!dirty || (*dirty)[b]) todo.push_back(static_cast<int>(b));
  tbb::parallel_for(std::size_t{0}, todo.size(), [&](std::size_t k) {
    const int b = todo[k];
    m.leaves[b] = band_leaf(g, field, kLeaf * (b % m.bx), kLeaf * (b / m.bx % m.by),
                            kLeaf * (b / (m.bx * m.by)));
  });
  return todo.size();
}

terrain::Mesh IsoMesher::mesh() const {
  init_openvdb();
  const Impl& m = *impl_;
  const terrain::Grid3Shape& g = m.shape;
  // A fresh tree of copies of the kept leaves: the same tree, and so the
  // same mesh, as one built from the whole field.
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  for (const auto& leaf : m.leaves)
    if (leaf) grid->tree().addLeaf(new Leaf(*leaf));
  return grid_mesh(g, *grid);
}

terrain::Mesh iso_surface(const terrain::Grid3Shape& g, const std::vector<float>& field,
                          IsoGrid kind) {
  if (kind == IsoGrid::Band) {
    IsoMesher mesher;
    mesher.update(g, field, nullptr);
    return mesher.mesh();
  }
  init_openvdb();
  return grid_mesh(g, *to_grid(g, field, -1.0f));
}

void write_density_vdb(const SoilState& s, const std::filesystem::path& path) {
  init_openvdb();
  const terrain::Grid3Shape& g = s.shape;
  auto transform = openvdb::math::Transform::createLinearTransform(g.voxel_size);
  transform->postTranslate(openvdb::Vec3d(g.origin.x() + 0.5 * g.voxel_size,
                                          g.origin.y() + 0.5 * g.voxel_size,
                                          g.origin.z() + 0.5 * g.voxel_size));
  // The wetness of the soil (thesis 5.3.4, for a renderer's wet coat): the
  // moisture field wherever there is soil.
  std::vector<float> wetness(s.size(), 0.0f);
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.rho[i] > 0) wetness[i] = s.wet[i];
  openvdb::GridPtrVec grids;
  for (auto [name, field] :
       {std::pair{"density", &s.rho}, std::pair{"collision", &s.psi},
        std::pair{"wetness", static_cast<const std::vector<float>*>(&wetness)}}) {
    openvdb::FloatGrid::Ptr grid = to_grid(g, *field, 1.0f);
    grid->setName(name);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(transform);
    grids.push_back(grid);
  }
  // Velocity (m/s) where there is soil: "velocity" is the name Blender and
  // Houdini read for motion blur.
  openvdb::Vec3SGrid::Ptr velocity = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  {
    auto acc = velocity->getAccessor();
    for (int y = 0; y < g.ny; ++y)
      for (int x = 0; x < g.nx; ++x)
        for (int z = 0; z < g.nz; ++z) {
          const std::size_t i = g.index(x, y, z);
          const openvdb::Vec3s v(s.ux[i], s.uy[i], s.uz[i]);
          if (s.rho[i] > 0 && v != openvdb::Vec3s(0.0f)) acc.setValue(openvdb::Coord(x, y, z), v);
        }
  }
  velocity->setName("velocity");
  velocity->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
  velocity->setTransform(transform);
  grids.push_back(velocity);
  std::string bytes;
  try {
    bytes = MemoryArchive().encode(grids);
  } catch (const openvdb::Exception& e) {
    throw Error("cannot write '" + path.string() + "': " + e.what());
  }
  stamp_content_uuid(bytes, path.string());
  AtomicFile out(path);
  write_all_bytes(out.temp_path(), bytes.data(), bytes.size(), path);
  out.commit();
}

}  // namespace drift::soil
