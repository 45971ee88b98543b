// The compact height-field geometry (render/height_field.h) against Embree's
// grid geometry over float3 vertices, which it replaces: the same triangles
// (the same diagonal), the same hit distances and normals on random, grazing,
// edge-aligned and upward rays, and no ray slipping between triangles.
#include "render/height_field.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "render/terrain_scene.h"
#include "terrain/error.h"
#include "tests/render/relief_fixture.h"

using namespace drift::render;
using drift::terrain::HeightField;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Rough relief of w x h cells of 2.5 m at UTM-sized coordinates: several
// wavelengths, steep faces, flat patches (equal heights make degenerate
// diagonals) and a few spikes.
HeightField relief(int w, int h) {
  return drift::testing::noisy_relief(w, h, 2.5, 7, [w, h](int x, int r, float noise) {
    float z = 40.0f * std::sin(x * 0.07f) * std::cos(r * 0.05f) + 6.0f * noise;
    if (x > w / 2 && r < h / 3) z = 10.0f;       // a plateau
    if ((x * 7 + r * 13) % 97 == 0) z += 30.0f;  // spikes
    return z;
  });
}

SceneInput input_of(const HeightField& dem) {
  SceneInput in;
  in.terrain = dem;
  in.surround.reach = 0.0;  // the DEM alone
  return in;
}

// The height of the triangulated surface at local (x, y): cell (c, r) split
// along v1 (c + 1, r) - v3 (c, r + 1), as Embree's grid geometry does.
float surface_z(const TerrainScene& scene, const HeightField& dem, float x, float y) {
  const Eigen::Vector3f nw =
      scene.to_local({dem.geo().cell_center(0, 0)[0], dem.geo().cell_center(0, 0)[1], 0.0});
  const float fx = (x - nw.x()) / 2.5f, fr = (nw.y() - y) / 2.5f;
  const int c = std::clamp(static_cast<int>(fx), 0, dem.width() - 2);
  const int r = std::clamp(static_cast<int>(fr), 0, dem.height() - 2);
  const float u = fx - c, v = fr - r;
  const float base = static_cast<float>(scene.origin().z());
  const auto z = [&](int cc, int rr) { return dem(cc, rr) - base; };
  if (u + v <= 1.0f) return z(c, r) + u * (z(c + 1, r) - z(c, r)) + v * (z(c, r + 1) - z(c, r));
  return z(c + 1, r + 1) + (1 - u) * (z(c, r + 1) - z(c + 1, r + 1)) +
         (1 - v) * (z(c + 1, r) - z(c + 1, r + 1));
}

struct Ray {
  Eigen::Vector3f o, d;
};

// Compares the two geometries on `rays`: the same hits and misses, hit
// distances within `rel` of each other, normals within 1e-4 where the ray
// meets a triangle's interior, and every hit on the triangulated surface.
// With `leaks`, rays along edges: where the grid's (Moeller-Trumbore) test
// lets a ray slip between two triangles, the watertight one must find the
// surface earlier instead; counted in `slipped`. Returns how many hit.
int compare(const TerrainScene& blocks, const TerrainScene& grid, const HeightField& dem,
            const std::vector<Ray>& rays, float rel, bool normals, int* slipped = nullptr) {
  int hits = 0;
  for (const Ray& ray : rays) {
    Eigen::Vector3f na, nb;
    const float a = blocks.hit_distance(ray.o, ray.d, &na);
    const float b = grid.hit_distance(ray.o, ray.d, &nb);
    if (a != kInf) {
      const Eigen::Vector3f p = ray.o + a * ray.d;
      EXPECT_NEAR(p.z(), surface_z(blocks, dem, p.x(), p.y()), 2e-3f);
    }
    if (slipped && a != kInf && (b == kInf || a < b - rel * std::max(1.0f, b))) {
      ++*slipped;
      continue;
    }
    if (a == kInf || b == kInf) {
      EXPECT_EQ(a, b) << "o " << ray.o.transpose() << " d " << ray.d.transpose();
      continue;
    }
    ++hits;
    EXPECT_NEAR(a, b, rel * std::max(1.0f, b))
        << "o " << ray.o.transpose() << " d " << ray.d.transpose();
    if (normals) {
      EXPECT_GT(na.dot(nb), 1.0f - 1e-4f) << na.transpose() << " / " << nb.transpose();
    }
  }
  return hits;
}

}  // namespace

TEST(HeightField, SameHitsAsGridGeometryOnRandomRays) {
  const HeightField dem = relief(150, 131);  // blocks and leaves cut at the edges
  const TerrainScene blocks(input_of(dem), TerrainGeometry::HeightField);
  const TerrainScene grid(input_of(dem), TerrainGeometry::Grid);
  const Eigen::Vector2f half = blocks.extent() / 2;
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Ray> down, grazing, below;
  for (int i = 0; i < 4000; ++i) {
    // From above, any downward direction.
    const Eigen::Vector3f o(u(rng) * half.x() * 1.2f, u(rng) * half.y() * 1.2f,
                            blocks.top() + 20.0f + 100.0f * std::abs(u(rng)));
    down.push_back({o, Eigen::Vector3f(u(rng), u(rng), -0.2f - std::abs(u(rng))).normalized()});
    // Grazing: just above the ground, 0.05 - 3 degrees down, across the DEM.
    const float x = u(rng) * half.x(), y = u(rng) * half.y();
    const float dip = (0.05f + 2.95f * std::abs(u(rng))) * static_cast<float>(M_PI) / 180.0f;
    const float az = u(rng) * static_cast<float>(M_PI);
    grazing.push_back({Eigen::Vector3f(x, y, blocks.height_at(x, y) + 3.0f),
                       Eigen::Vector3f(std::cos(dip) * std::cos(az), std::cos(dip) * std::sin(az),
                                       -std::sin(dip))});
    // From below the lowest ground, upwards: the terrain's underside.
    below.push_back({Eigen::Vector3f(u(rng) * half.x(), u(rng) * half.y(), blocks.bottom() - 50.0f),
                     Eigen::Vector3f(0.5f * u(rng), 0.5f * u(rng), 1.0f).normalized()});
  }
  EXPECT_GT(compare(blocks, grid, dem, down, 1e-5f, true), 1500);
  // A grazing ray's distance moves by a height's rounding over the sine of
  // its dip: 1e-4 of the distance at 0.05 degrees.
  EXPECT_GT(compare(blocks, grid, dem, grazing, 1e-4f, true), 2000);
  EXPECT_GT(compare(blocks, grid, dem, below, 1e-5f, true), 3300);
}

TEST(HeightField, SameHitsAlongCellEdgesAndDiagonals) {
  const HeightField dem = relief(70, 66);
  const TerrainScene blocks(input_of(dem), TerrainGeometry::HeightField);
  const TerrainScene grid(input_of(dem), TerrainGeometry::Grid);
  // Vertex (c, r) in local coordinates, from the DEM's own cell centres.
  const auto vertex = [&](int c, int r) {
    const auto p = dem.geo().cell_center(c, r);
    return blocks.to_local({p[0], p[1], 0.0});
  };
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> col(2, 67), row(2, 63);
  std::uniform_real_distribution<float> dip(0.02f, 1.2f);
  std::vector<Ray> rays;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3f v = vertex(col(rng), row(rng));
    const float s = dip(rng), h = blocks.top() + 5.0f;
    // In the vertical planes of a column, of a row, of a cell diagonal
    // (v1 -> v3: west and south at once) and of the other diagonal.
    for (const Eigen::Vector2f& along : {Eigen::Vector2f(0, 1), Eigen::Vector2f(1, 0),
                                         Eigen::Vector2f(-1, -1), Eigen::Vector2f(1, -1)}) {
      const Eigen::Vector2f a = along.normalized();
      const Eigen::Vector3f d = Eigen::Vector3f(a.x(), a.y(), -s).normalized();
      rays.push_back({Eigen::Vector3f(v.x(), v.y(), h) - d * (h / std::abs(d.z())) * 0.5f, d});
    }
  }
  // Rays in an edge's plane meet the surface on the edge itself, where both
  // triangles (and both geometries) may claim it: distances only. Embree's
  // grid lets some slip through between its triangles (167 of 12000 here).
  int slipped = 0;
  EXPECT_GT(compare(blocks, grid, dem, rays, 1e-5f, false, &slipped), 3500);
  EXPECT_LT(slipped, 400);
}

TEST(HeightField, NoRaySlipsBetweenTriangles) {
  // Straight down onto every vertex, every edge's midpoint and every
  // diagonal's midpoint: each must hit at the surface's height there.
  const HeightField dem = relief(40, 37);
  const TerrainScene blocks(input_of(dem), TerrainGeometry::HeightField);
  // Vertices on the very floats the scene places them at (x0 + c dx,
  // y0 - r dy), so that rays through them lie exactly on edges; midpoints
  // as near as floats get.
  const auto nw = dem.geo().cell_center(0, 0);
  const Eigen::Vector3f x0 = blocks.to_local({nw[0], nw[1], 0.0});
  const auto local = [&](double c, double r) {
    return Eigen::Vector3f(x0.x() + static_cast<float>(c) * 2.5f,
                           x0.y() - static_cast<float>(r) * 2.5f, 0.0f);
  };
  const float base = static_cast<float>(blocks.origin().z());
  const Eigen::Vector3f down(0, 0, -1);
  const float h = blocks.top() + 10.0f;
  int missed = 0;
  for (int r = 0; r + 1 < dem.height(); ++r)
    for (int c = 0; c + 1 < dem.width(); ++c) {
      const std::array<std::pair<Eigen::Vector3f, float>, 4> targets = {{
          {local(c, r), dem(c, r) - base},
          {local(c + 0.5, r), 0.5f * (dem(c, r) + dem(c + 1, r)) - base},
          {local(c, r + 0.5), 0.5f * (dem(c, r) + dem(c, r + 1)) - base},
          {local(c + 0.5, r + 0.5), 0.5f * (dem(c + 1, r) + dem(c, r + 1)) - base},  // v1-v3
      }};
      for (const auto& [p, z] : targets) {
        const float t = blocks.hit_distance(Eigen::Vector3f(p.x(), p.y(), h), down);
        if (t == kInf) {
          if (missed < 6)
            ADD_FAILURE() << "miss c " << c << " r " << r << " p " << p.transpose() << " z " << z;
          ++missed;
          continue;
        }
        EXPECT_NEAR(h - t, z, 1e-3f) << "cell " << c << ", " << r;
      }
    }
  EXPECT_EQ(missed, 0);
}

// Every hit on the DEM lies within the ray's reach of a point on an edge:
// oblique rays, from every side and at dips from 0.5 to 80 degrees, aimed at
// points on cell edges and diagonals (on the surface as floats place them)
// must meet the surface there, not beyond, where they cross it there (count
// in `crossing`). A ray that slips between the two triangles of an edge runs
// on to a farther slope or into the sky. Returns how many slipped.
int slips_at_edges(const TerrainScene& scene, const HeightField& dem, int count, int seed,
                   int* crossing) {
  const auto nw = dem.geo().cell_center(0, 0);
  const Eigen::Vector3f x0 = scene.to_local({nw[0], nw[1], 0.0});
  const float base = static_cast<float>(scene.origin().z());
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> col(1, dem.width() - 3), row(1, dem.height() - 3), kind(0, 2);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  int slipped = 0;
  for (int k = 0; k < count; ++k) {
    const int c = col(rng), r = row(rng);
    const float s = unit(rng);
    // A point on the cell's north edge, west edge or v1-v3 diagonal, with the
    // surface's height there by the same linear interpolation.
    float fc = static_cast<float>(c), fr = static_cast<float>(r), z = 0.0f;
    const auto h = [&](int cc, int rr) { return dem(cc, rr) - base; };
    switch (kind(rng)) {
      case 0:
        fc += s, z = h(c, r) + s * (h(c + 1, r) - h(c, r));
        break;
      case 1:
        fr += s, z = h(c, r) + s * (h(c, r + 1) - h(c, r));
        break;
      default:
        fc += 1.0f - s, fr += s, z = h(c + 1, r) + s * (h(c, r + 1) - h(c + 1, r));
        break;
    }
    const Eigen::Vector3f target(x0.x() + fc * 2.5f, x0.y() - fr * 2.5f, z);
    const float az = unit(rng) * 2.0f * static_cast<float>(M_PI);
    const float dip = (0.5f + 79.5f * unit(rng)) * static_cast<float>(M_PI) / 180.0f;
    const Eigen::Vector3f d(std::cos(dip) * std::cos(az), std::cos(dip) * std::sin(az),
                            -std::sin(dip));
    // From 30 m back along the ray: close enough that no other slope is in
    // the way of most rays, and any that is shortens the hit, never lengthens it.
    const float reach = 30.0f;
    const Eigen::Vector3f o = target - d * reach;
    // Only rays that cross the surface there: above it at their start and
    // clearly below it just past the point (a ray may also touch a ridge's
    // edge and stay above the ground, and so miss by rounding, rightly).
    const float past = 0.05f;
    const Eigen::Vector3f after = target + d * past;
    // ... and over the DEM all the way (no ground beyond its edge to cross).
    const float oc = (o.x() - x0.x()) / 2.5f, orow = (x0.y() - o.y()) / 2.5f;
    if (oc < 0.5f || oc > dem.width() - 1.5f || orow < 0.5f || orow > dem.height() - 1.5f) continue;
    if (!(o.z() > surface_z(scene, dem, o.x(), o.y())) ||
        !(after.z() < surface_z(scene, dem, after.x(), after.y()) - 1e-4f))
      continue;
    ++*crossing;
    const float t = scene.hit_distance(o, d);
    if (!(t <= reach + past)) ++slipped;
  }
  return slipped;
}

TEST(HeightField, NoObliqueRaySlipsThroughAnEdge) {
  const HeightField dem = relief(70, 66);
  const TerrainScene blocks(input_of(dem), TerrainGeometry::HeightField);
  int crossing = 0;
  EXPECT_EQ(slips_at_edges(blocks, dem, 40000, 11, &crossing), 0);
  EXPECT_GT(crossing, 20000);
  // The check sees slips where there are some: Embree's grid geometry (not
  // watertight) lets rays through here.
  const TerrainScene grid(input_of(dem), TerrainGeometry::Grid);
  EXPECT_GT(slips_at_edges(grid, dem, 40000, 11, &crossing), 0);
}

// The min-max tree and each leaf row's range of cells only skip cells the
// ray cannot meet: the walk gives the hit that testing every cell of the
// field gives, to the bit, on rays of every kind (grazing along rows and
// columns, axis-parallel, straight down, from below).
TEST(HeightField, WalkFindsTheHitOfEveryCell) {
  const HeightField dem = relief(75, 58);  // leaves and blocks cut at the edges
  HeightGrid grid;
  grid.width = dem.width(), grid.height = dem.height();
  grid.x0 = 12.5f, grid.y0 = 140.0f, grid.dx = 2.5f, grid.dy = 2.5f;
  for (int r = 0; r < dem.height(); ++r)
    for (int c = 0; c < dem.width(); ++c) grid.z.push_back(dem(c, r));
  const HeightFieldBlocks blocks(grid);
  float lo = kInf, hi = -kInf;
  for (float z : grid.z) lo = std::min(lo, z), hi = std::max(hi, z);
  const float w = grid.dx * (grid.width - 1), h = grid.dy * (grid.height - 1);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int hits = 0;
  for (int i = 0; i < 6000; ++i) {
    Eigen::Vector3f o(grid.x0 + u(rng) * w, grid.y0 - u(rng) * h, hi + 5.0f);
    Eigen::Vector3f d;
    switch (i % 6) {
      case 0:
        d = {u(rng) - 0.5f, u(rng) - 0.5f, -u(rng)};
        break;  // down, any way
      case 1:   // grazing, low over the ground
        o.z() = lo + (hi - lo) * u(rng);
        d = {u(rng) - 0.5f, u(rng) - 0.5f, -0.02f * u(rng)};
        break;
      case 2:
        d = {1.0f, 0.0f, -0.05f * u(rng)};
        break;  // along a row
      case 3:
        d = {0.0f, -1.0f, -0.05f * u(rng)};
        break;  // along a column
      case 4:
        d = {0.0f, 0.0f, -1.0f};
        break;  // straight down
      default:  // from below, upwards
        o.z() = lo - 5.0f;
        d = {u(rng) - 0.5f, u(rng) - 0.5f, 1.0f};
        break;
    }
    if (i % 6 == 1 || i % 6 == 2) o.x() = grid.x0 - 1.0f;  // enter from the west edge
    if (i % 6 == 3) o.y() = grid.y0 + 1.0f;                // from the north edge
    d.normalize();
    const HeightRay ray(o, d);
    float t_walk = kInf, t_all = kInf;
    HeightHit a, b;
    for (unsigned block = 0; block < blocks.block_count(); ++block)
      blocks.intersect(block, ray, 0.0f, t_walk, a);
    blocks.intersect_every_cell(ray, 0.0f, t_all, b);
    ASSERT_EQ(t_walk, t_all) << "ray " << i << " o " << o.transpose() << " d " << d.transpose();
    if (t_all != kInf) ++hits;
  }
  EXPECT_GT(hits, 2000);
}

// Auto takes the height field from kHeightFieldMinCells cells on, for a DEM
// handed over (as drift render does) as for one copied. The count was taken
// after the handed-over DEM had been emptied, so drift render traced every
// DEM in core on Embree's grid (36 B a cell; issue 36: the 16384^2 peak of
// 40 B a cell, and the pixels that differed from the out-of-core render).
TEST(HeightField, AutoTakesTheHeightFieldForALargeAdoptedDem) {
  HeightField dem(4096, 4096, 0.0f, drift::terrain::local_georeference(1.0));
  for (int r = 0; r < dem.height(); ++r)
    for (int c = 0; c < dem.width(); ++c) dem(c, r) = static_cast<float>((c * 7 + r * 3) % 50);
  ASSERT_EQ(dem.size(), kHeightFieldMinCells);
  const std::size_t cells = dem.size();
  SceneInput in;
  in.surround.reach = 0.0;
  const TerrainScene adopted(in, std::move(dem));
  // 4 B of height a cell and the min-max tree, against 12 B of float3 vertex.
  EXPECT_LT(adopted.terrain_bytes(), cells * 5);
}

TEST(HeightField, AdoptedRasterGivesTheSameScene) {
  const HeightField dem = relief(90, 40);
  const SceneInput in = input_of(dem);
  const TerrainScene copied(in, TerrainGeometry::HeightField);
  HeightField moved = dem;
  const TerrainScene adopted(in, std::move(moved), TerrainGeometry::HeightField);
  EXPECT_TRUE(moved.empty());
  EXPECT_EQ(copied.origin(), adopted.origin());
  EXPECT_EQ(copied.top(), adopted.top());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3f o(u(rng) * 100, u(rng) * 40, 200.0f);
    const Eigen::Vector3f d = Eigen::Vector3f(u(rng), u(rng), -1.0f).normalized();
    EXPECT_EQ(copied.hit_distance(o, d), adopted.hit_distance(o, d));
  }
  // 4 B of height a cell and the min-max tree, against 12 B of float3 vertex.
  EXPECT_LT(copied.terrain_bytes(), dem.size() * 5);
  EXPECT_GE(TerrainScene(in, TerrainGeometry::Grid).terrain_bytes(), dem.size() * 16);
}
