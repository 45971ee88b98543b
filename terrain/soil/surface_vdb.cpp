// The one file that includes OpenVDB (a heavy header: docs/architecture.md,
// Debian 12 packages).
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
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

// IsoMesher: OpenVDB's volumeToMesh at adaptivity 0 (dual marching cubes:
// one point per edge group of a cell, sEdgeGroupTable; one quad per grid edge
// whose ends lie across the iso-value, joining the points of the four cells
// round it; ambiguous faces corrected as correctCellSigns does), done on
// the dense field block by block so that a frame redoes only the blocks
// whose field changed and keeps the others' points and quads (issue 33,
// item 1: volumeToMesh rebuilt its trees over the whole grid every frame,
// 40 % of a 64^3 frame). The cells and the points are OpenVDB's own
// (computeCellPoints from its header), so the surface is volumeToMesh's
// vertex for vertex and quad for quad, in another order
// (SoilSurface.BlockMesherGivesVolumeToMeshsSurface). Seams match by
// construction: a quad names its four cells and their edge, and is resolved
// to point numbers only when the blocks are joined.
namespace {

namespace vtm = openvdb::tools::volume_to_mesh_internal;

// Cells are the cubes between voxel centres, named by their lowest corner
// voxel c in [-1, n - 1] per axis (the field is 0 outside the grid, so the
// surface closes at the grid's sides); cell c and the grid edges starting
// at voxel c belong to block (c + 1) / kLeaf per axis.
constexpr int kB = IsoMesher::kLeaf;

struct CellRef {
  std::uint32_t cell;  // (x + 1) + (nx + 1) ((y + 1) + (ny + 1) (z + 1))
  std::uint8_t edge;   // the quad's edge in that cell (sEdgeGroupTable's 1-12)
};

struct Block {
  std::vector<Eigen::Vector3f> points;  // metres
  std::vector<std::uint16_t> first;     // per cell of the block: its first point
  std::vector<std::uint8_t> signs;      // per cell: corrected sign flags
  std::vector<std::array<CellRef, 4>> quads;
};

struct Field {
  const terrain::Grid3Shape& g;
  const std::vector<float>& f;
  // The value volumeToMesh reads: the negated field (inside below -0.5).
  double at(int x, int y, int z) const {
    return g.contains(x, y, z) ? -static_cast<double>(f[g.index(x, y, z)]) : -0.0;
  }
  bool inside(int x, int y, int z) const {
    return g.contains(x, y, z) && -f[g.index(x, y, z)] < -0.5f;
  }
  std::array<double, 8> values(int x, int y, int z) const {
    return {at(x, y, z),     at(x + 1, y, z),     at(x + 1, y, z + 1),     at(x, y, z + 1),
            at(x, y + 1, z), at(x + 1, y + 1, z), at(x + 1, y + 1, z + 1), at(x, y + 1, z + 1)};
  }
};

}  // namespace

struct IsoMesher::Impl {
  terrain::Grid3Shape shape;
  int bx = 0, by = 0, bz = 0;  // blocks a side: n / kB + 1
  std::vector<Block> blocks;   // x fastest, then y, then z
  std::uint32_t cell_id(int x, int y, int z) const {
    return static_cast<std::uint32_t>((x + 1) +
                                      (shape.nx + 1) * ((y + 1) + (shape.ny + 1) * (z + 1)));
  }
  void build(const Field& f, int b);
};

void IsoMesher::Impl::build(const Field& f, int b) {
  Block& blk = blocks[b];
  blk.points.clear();
  blk.quads.clear();
  blk.first.assign(kB * kB * kB, 0);
  blk.signs.assign(kB * kB * kB, 0);
  const int X = kB * (b % bx) - 1, Y = kB * (b / bx % by) - 1, Z = kB * (b / (bx * by)) - 1;
  const terrain::Grid3Shape& g = shape;
  const double h = g.voxel_size;
  // Which voxels the block reads are inside, from X - 1 to X + kB + 1 per
  // axis; a block all inside or all outside has no surface.
  constexpr int W = kB + 3;
  std::array<std::uint8_t, W * W * W> in{};
  int count = 0;
  for (int z = 0; z < W; ++z)
    for (int y = 0; y < W; ++y)
      for (int x = 0; x < W; ++x) {
        const bool v = f.inside(X - 1 + x, Y - 1 + y, Z - 1 + z);
        in[(z * W + y) * W + x] = v;
        count += v;
      }
  if (count == 0 || count == W * W * W) {
    blk = Block{};
    return;
  }
  // Cell signs as Field::signs, from the local flags (x, y, z: voxel
  // coordinates).
  auto inside = [&](int x, int y, int z) {
    return in[((z - Z + 1) * W + (y - Y + 1)) * W + (x - X + 1)] != 0;
  };
  auto signs = [&](int x, int y, int z) {
    static constexpr int kC[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1},
                                     {0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}};
    unsigned s = 0;
    for (int k = 0; k < 8; ++k)
      if (inside(x + kC[k][0], y + kC[k][1], z + kC[k][2])) s |= 1u << k;
    return static_cast<std::uint8_t>(s);
  };
  bool any = false;
  // Points of the block's cells (ComputePoints at adaptivity 0).
  for (int lz = 0; lz < kB; ++lz)
    for (int ly = 0; ly < kB; ++ly)
      for (int lx = 0; lx < kB; ++lx) {
        const int x = X + lx, y = Y + ly, z = Z + lz;
        if (x >= g.nx || y >= g.ny || z >= g.nz) continue;
        const std::uint8_t raw = signs(x, y, z);
        if (raw == 0 || raw == 0xFF) continue;
        // correctCellSigns: a cell with an ambiguous face takes the
        // complement when the cell across that face is ambiguous on it too.
        static constexpr int kN[7][4] = {{0, 0, 0, 0},  {0, 0, -1, 3}, {1, 0, 0, 4}, {0, 0, 1, 1},
                                         {-1, 0, 0, 2}, {0, -1, 0, 6}, {0, 1, 0, 5}};
        std::uint8_t s = raw;
        if (const int face = vtm::sAmbiguousFace[raw]; face != 0) {
          const int* o = kN[face];
          if (vtm::sAmbiguousFace[signs(x + o[0], y + o[1], z + o[2])] == o[3])
            s = static_cast<std::uint8_t>(~raw);
        }
        const int c = (lz * kB + ly) * kB + lx;
        blk.signs[c] = s;
        blk.first[c] = static_cast<std::uint16_t>(blk.points.size());
        std::array<openvdb::Vec3d, 4> pts;
        const std::size_t n = vtm::computeCellPoints(pts, f.values(x, y, z), s, -0.5);
        for (std::size_t k = 0; k < n; ++k) {
          const openvdb::Vec3d p = pts[k] + openvdb::Vec3d(x, y, z);
          // As volumeToMesh's float points, then grid_mesh's metres.
          const openvdb::Vec3s q(static_cast<float>(p[0]), static_cast<float>(p[1]),
                                 static_cast<float>(p[2]));
          blk.points.push_back(
              (g.origin + h * Eigen::Vector3d(q.x() + 0.5, q.y() + 0.5, q.z() + 0.5))
                  .cast<float>());
        }
        any = true;
      }
  if (!any) {
    blk = Block{};
    return;
  }
  // Quads of the grid edges starting at the block's cells' lowest corners
  // (constructPolygons; the grid is not a level set, so volumeToMesh inverts
  // the orientation).
  for (int lz = 0; lz < kB; ++lz)
    for (int ly = 0; ly < kB; ++ly)
      for (int lx = 0; lx < kB; ++lx) {
        const int x = X + lx, y = Y + ly, z = Z + lz;
        if (x >= g.nx || y >= g.ny || z >= g.nz) continue;
        const bool here = inside(x, y, z);
        const bool flip = !here;  // isInside, inverted
        auto add = [&](bool reverse, CellRef a, CellRef b1, CellRef c, CellRef d) {
          if (!reverse)
            blk.quads.push_back({a, b1, c, d});
          else
            blk.quads.push_back({d, c, b1, a});
        };
        if (here != inside(x + 1, y, z))
          add(flip, {cell_id(x, y, z), 1}, {cell_id(x, y - 1, z), 5}, {cell_id(x, y - 1, z - 1), 7},
              {cell_id(x, y, z - 1), 3});
        if (here != inside(x, y + 1, z))
          add(flip, {cell_id(x, y, z), 9}, {cell_id(x, y, z - 1), 12},
              {cell_id(x - 1, y, z - 1), 11}, {cell_id(x - 1, y, z), 10});
        if (here != inside(x, y, z + 1))
          add(!flip, {cell_id(x, y, z), 4}, {cell_id(x, y - 1, z), 8},
              {cell_id(x - 1, y - 1, z), 6}, {cell_id(x - 1, y, z), 2});
      }
}

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
    m.bx = g.nx / kB + 1;
    m.by = g.ny / kB + 1;
    m.bz = g.nz / kB + 1;
    m.blocks.clear();
    m.blocks.resize(static_cast<std::size_t>(m.bx) * m.by * m.bz);
    dirty = nullptr;
  }
  // Block b's cells read the voxels from one before its first cell to two
  // after its last (a cell's corners, and the cell across an ambiguous
  // face), so they lie in leaves b - 1 to b + 1 per axis: rebuild a block if
  // any of those leaves is flagged (every changed voxel's leaf is).
  const int lx = (g.nx + kB - 1) / kB, ly = (g.ny + kB - 1) / kB, lz = (g.nz + kB - 1) / kB;
  std::vector<int> todo;
  for (int b = 0; b < static_cast<int>(m.blocks.size()); ++b) {
    bool redo = !dirty;
    const int u = b % m.bx, v = b / m.bx % m.by, w = b / (m.bx * m.by);
    for (int z = std::max(0, w - 1); z <= std::min(lz - 1, w + 1) && !redo; ++z)
      for (int y = std::max(0, v - 1); y <= std::min(ly - 1, v + 1) && !redo; ++y)
        for (int x = std::max(0, u - 1); x <= std::min(lx - 1, u + 1) && !redo; ++x)
          redo = (*dirty)[(static_cast<std::size_t>(z) * ly + y) * lx + x] != 0;
    if (redo) todo.push_back(b);
  }
  const Field f{g, field};
  tbb::parallel_for(std::size_t{0}, todo.size(), [&](std::size_t k) { m.build(f, todo[k]); });
  return todo.size();
}

terrain::Mesh IsoMesher::mesh() const {
  const Impl& m = *impl_;
  const int cx = m.shape.nx + 1, cy = m.shape.ny + 1;
  std::vector<std::uint32_t> offset(m.blocks.size() + 1, 0);
  std::size_t quads = 0;
  for (std::size_t b = 0; b < m.blocks.size(); ++b) {
    offset[b + 1] = offset[b] + static_cast<std::uint32_t>(m.blocks[b].points.size());
    quads += m.blocks[b].quads.size();
  }
  terrain::Mesh mesh;
  mesh.positions.reserve(offset.back());
  for (const Block& blk : m.blocks)
    mesh.positions.insert(mesh.positions.end(), blk.points.begin(), blk.points.end());
  // A cell's point for the group its edge belongs to.
  auto point = [&](const CellRef& r) {
    const int x = static_cast<int>(r.cell % cx), y = static_cast<int>(r.cell / cx % cy),
              z = static_cast<int>(r.cell / (static_cast<std::uint32_t>(cx) * cy));
    const int b = (z / kB * m.by + y / kB) * m.bx + x / kB;  // x, y, z here are cell + 1
    const int c = ((z % kB) * kB + y % kB) * kB + x % kB;
    const Block& blk = m.blocks[b];
    const std::uint8_t s = blk.signs[c];
    const int sub = vtm::sEdgeGroupTable[s][0] > 1 ? vtm::sEdgeGroupTable[s][r.edge] - 1 : 0;
    return static_cast<int>(offset[b] + blk.first[c] + sub);
  };
  mesh.triangles.reserve(2 * quads);
  for (const Block& blk : m.blocks)
    for (const auto& q : blk.quads) {
      const int a = point(q[0]), b = point(q[1]), c = point(q[2]), d = point(q[3]);
      mesh.triangles.push_back({a, b, c});
      mesh.triangles.push_back({a, c, d});
    }
  return mesh;
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
