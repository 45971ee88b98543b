#include "render/surround.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "render/material.h"
#include "render/procedural_noise.h"
#include "render/surface.h"
#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::render {

namespace {

constexpr double kEarthRadius = 6371000.0;
constexpr int kOutwardSteps = 64;    // rows of a strip from the edge to the reach
constexpr int kMaxGridSide = 32767;  // Embree's RTCGrid sides are 16-bit
constexpr std::uint64_t kRidgeSeed = 0x5a77a0d;
constexpr double kRidgeLargest = 9000.0, kRidgeSmallest = 150.0;  // metres
constexpr float kRidgeHurst = 0.8f;

// Ridged noise (Musgrave 1994, in Ebert et al., "Texturing and Modeling",
// ch. 16): each octave (1 - |n|)^2 less its mean (0.45, measured) has sharp
// crests and round valleys; octaves the grid cannot resolve (shorter than two
// `spacing`s) fade out. The sum's amplitude at the largest octave is 1.
float ridges(double x, double y, float spacing) {
  float sum = 0.0f;
  int i = 0;
  for (double w = kRidgeLargest; w >= kRidgeSmallest; w *= 0.5, ++i) {
    const float keep = static_cast<float>(std::clamp(w / spacing - 1.0, 0.0, 1.0));
    if (keep <= 0.0f) break;
    const float n = value_noise(x / w + 0.31 * i, y / w - 0.57 * i, kRidgeSeed + i).value;
    const float r = (1.0f - std::abs(n)) * (1.0f - std::abs(n)) - 0.45f;
    sum += keep * static_cast<float>(std::pow(w / kRidgeLargest, kRidgeHurst)) * r;
  }
  return sum;
}

// Distances of the strip's rows from the edge: 0, first, ... growing by a
// constant ratio to `reach` (fine at the seam, coarse far away).
std::vector<double> outward_distances(double first, double reach) {
  double lo = 1.0 + 1e-9, hi = 4.0;
  auto total = [&](double g) { return first * (std::pow(g, kOutwardSteps) - 1.0) / (g - 1.0); };
  if (total(hi) < reach) hi = 64.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (total(mid) < reach ? lo : hi) = mid;
  }
  std::vector<double> d(kOutwardSteps + 1, 0.0);
  const double g = 0.5 * (lo + hi);
  for (int k = 1; k <= kOutwardSteps; ++k) d[k] = first * (std::pow(g, k) - 1.0) / (g - 1.0);
  if (reach <= first * kOutwardSteps) {  // a short reach: even steps
    for (int k = 0; k <= kOutwardSteps; ++k) d[k] = reach * k / kOutwardSteps;
  }
  return d;
}

}  // namespace

SurroundHeight::SurroundHeight(const DemVertices& dem, const SurroundOptions& options)
    : dem_(dem), options_(&options) {
  x0_ = dem.heights->x0, y0_ = dem.heights->y0;
  x1_ = x0_ + (dem.width - 1) * dem.dx, y1_ = y0_ - (dem.height - 1) * dem.dy;
  double s = dem.sum, s2 = dem.sum_squares;
  if (!dem.quantised)
    for (const float z : dem.heights->z) s += z, s2 += double(z) * z;
  const double n = static_cast<double>(dem.width) * dem.height;
  mean_ = static_cast<float>(s / n);
  deviation_ = static_cast<float>(std::sqrt(std::max(0.0, s2 / n - (s / n) * (s / n))));
  decay_ = 0.125f * ((x1_ - x0_) + (y0_ - y1_));
  // Cumulative integral of the heights along the perimeter (trapezoids),
  // clockwise from the north-west corner.
  const auto z = [&](int c, int r) { return dem.at(c, r); };
  std::vector<std::pair<float, float>> loop;  // (step length, height) per perimeter vertex
  loop.reserve(2 * static_cast<std::size_t>(dem.width + dem.height));
  for (int c = 0; c < dem.width; ++c) loop.emplace_back(c ? dem.dx : 0.0f, z(c, 0));
  for (int r = 1; r < dem.height; ++r) loop.emplace_back(dem.dy, z(dem.width - 1, r));
  for (int c = dem.width - 2; c >= 0; --c) loop.emplace_back(dem.dx, z(c, dem.height - 1));
  for (int r = dem.height - 2; r >= 1; --r) loop.emplace_back(dem.dy, z(0, r));
  sat_.assign(loop.size(), 0.0);
  for (std::size_t i = 1; i < loop.size(); ++i)
    sat_[i] = sat_[i - 1] + 0.5 * loop[i].first * (loop[i].second + loop[i - 1].second);
}

float SurroundHeight::outside_distance(float x, float y) const {
  const float cx = std::clamp(x, x0_, x1_), cy = std::clamp(y, y1_, y0_);
  return std::hypot(x - cx, y - cy);
}

float SurroundHeight::dem_height(float x, float y) const {
  const float fx = std::clamp((x - x0_) / dem_.dx, 0.0f, dem_.width - 1.0f);
  const float fr = std::clamp((y0_ - y) / dem_.dy, 0.0f, dem_.height - 1.0f);
  const int c = std::min(static_cast<int>(fx), dem_.width - 2);
  const int r = std::min(static_cast<int>(fr), dem_.height - 2);
  const float tx = fx - c, tr = fr - r;
  const auto z = [&](int cc, int rr) { return dem_.at(cc, rr); };
  return (1 - tr) * ((1 - tx) * z(c, r) + tx * z(c + 1, r)) +
         tr * ((1 - tx) * z(c, r + 1) + tx * z(c + 1, r + 1));
}

float SurroundHeight::edge_mean(float x, float y, float half_width) const {
  // Perimeter position t of the edge point (x, y), clockwise from the NW corner.
  const float w = x1_ - x0_, h = y0_ - y1_, perimeter = 2 * (w + h);
  float t;
  if (y >= y0_)
    t = x - x0_;
  else if (x >= x1_)
    t = w + (y0_ - y);
  else if (y <= y1_)
    t = w + h + (x1_ - x);
  else
    t = 2 * w + h + (y - y1_);
  // The integral of the heights up to perimeter position u (wrapping).
  const std::size_t n = sat_.size();
  const double total = sat_.back() + 0.5 * dem_.dy * (dem_.at(0, 0) + dem_.at(0, 1));
  auto integral = [&](double u) {
    const double laps = std::floor(u / perimeter);
    u -= laps * perimeter;
    // Vertex index along the loop: binary search on the cumulative lengths
    // is avoided by the fixed spacing of each side.
    double i;
    if (u <= w)
      i = u / dem_.dx;
    else if (u <= w + h)
      i = (dem_.width - 1) + (u - w) / dem_.dy;
    else if (u <= 2 * w + h)
      i = (dem_.width - 1) + (dem_.height - 1) + (u - w - h) / dem_.dx;
    else
      i = 2.0 * (dem_.width - 1) + (dem_.height - 1) + (u - 2 * w - h) / dem_.dy;
    const std::size_t a = std::min(static_cast<std::size_t>(i), n - 1);
    const double next = a + 1 < n ? sat_[a + 1] : total;
    return laps * total + sat_[a] + (i - a) * (next - sat_[a]);
  };
  const float half = std::min(half_width, 0.5f * perimeter);
  return static_cast<float>((integral(t + half) - integral(t - half)) / (2.0 * half));
}

std::optional<SurroundHeight::RasterSample> SurroundHeight::raster_height(float x, float y) const {
  const double wx = dem_.origin.x() + x, wy = dem_.origin.y() + y;
  const terrain::HeightField* finest = nullptr;
  float value = NAN;
  for (const terrain::HeightField& r : options_->rasters) {
    const float v = sample_raster(r, wx, wy, NAN);
    if (std::isnan(v)) continue;
    if (!finest || r.geo().cell_size_x() < finest->geo().cell_size_x()) finest = &r, value = v;
  }
  if (!finest) return std::nullopt;
  return RasterSample{static_cast<float>(value * dem_.exaggeration - dem_.origin.z()),
                      finest->geo().cell_size_x()};
}

float SurroundHeight::operator()(float x, float y, float spacing) const {
  const float d = outside_distance(x, y);
  if (d <= 0.0f) return dem_height(x, y);
  const float cx = std::clamp(x, x0_, x1_), cy = std::clamp(y, y1_, y0_);
  const float drop = static_cast<float>(double(d) * d / (2.0 * kEarthRadius)) * dem_.exaggeration;
  const std::optional<RasterSample> raster = raster_height(x, y);
  if (!raster) return continued_edge(x, y, d, spacing) - drop;
  const double blend = options_->blend > 0.0 ? options_->blend : 10.0 * raster->cell;
  const float weight = smoothstep(0.0f, static_cast<float>(blend), d);
  if (const std::optional<RasterSample> at_edge = raster_height(cx, cy)) {
    // The raster shifted by the seam's mismatch, the shift fading out: a
    // surround the DEM was cut from goes on as itself (blending towards the
    // continued edge instead laid a false, flattened band of `blend` metres
    // round a crop), a coarser one meets the edge without a step.
    return raster->z + (1.0f - weight) * (dem_height(cx, cy) - at_edge->z) - drop;
  }
  // A raster that does not reach the edge: blended in from the continued edge.
  return (1.0f - weight) * continued_edge(x, y, d, spacing) + weight * raster->z - drop;
}

float SurroundHeight::continued_edge(float x, float y, float d, float spacing) const {
  const float cx = std::clamp(x, x0_, x1_), cy = std::clamp(y, y1_, y0_);
  // The edge continued: from the edge's own height at the seam to a mean
  // over a window growing with d, relaxing to the DEM's mean height.
  const float cell = std::max(dem_.dx, dem_.dy);
  const float near = smoothstep(0.0f, 2.0f * cell, d);
  const float edge = (1 - near) * dem_height(cx, cy) + near * edge_mean(cx, cy, 0.5f * d + cell);
  const float relax = std::exp(-d / decay_);
  float z = mean_ + (edge - mean_) * relax;
  // Ridges growing in from the edge, no finer than the grid there, as
  // high as the DEM's own relief (three times its height deviation).
  z += smoothstep(0.0f, decay_, d) * 3.0f * deviation_ *
       ridges(dem_.origin.x() + x, dem_.origin.y() + y, spacing);
  return z;
}

namespace {

// Vertex normals of a block of nx x ny vertices from `start` (row-major):
// the cross product of the central differences along its two directions
// (one-sided at its borders), turned up.
void add_normals(SurroundGrids& out, unsigned start, int nx, int ny) {
  out.normals.resize(out.vertices.size());
  auto at = [&](int i, int j) -> const Eigen::Vector3f& {
    return out.vertices[start + static_cast<std::size_t>(j) * nx + i];
  };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const Eigen::Vector3f du = at(std::min(i + 1, nx - 1), j) - at(std::max(i - 1, 0), j);
      const Eigen::Vector3f dv = at(i, std::min(j + 1, ny - 1)) - at(i, std::max(j - 1, 0));
      Eigen::Vector3f n = du.cross(dv);
      if (n.z() < 0.0f) n = -n;
      const float length = n.norm();
      out.normals[start + static_cast<std::size_t>(j) * nx + i] =
          length > 0.0f ? Eigen::Vector3f(n / length) : Eigen::Vector3f(0, 0, 1);
    }
  }
}

}  // namespace

SurroundGrids build_surround(const DemVertices& dem, const SurroundOptions& options) {
  SurroundGrids out;
  if (!(options.reach > 0.0)) return out;
  const SurroundHeight height(dem, options);
  const std::vector<double> d = outward_distances(std::min(dem.dx, dem.dy), options.reach);
  const int k = kOutwardSteps + 1;
  const std::size_t count = 2 * static_cast<std::size_t>(k) * (dem.width + dem.height) +
                            4 * static_cast<std::size_t>(k) * k;
  require_memory(2 * count * sizeof(Eigen::Vector3f), "the ground around the DEM",
                 "set [terrain] surround_reach = 0");
  out.vertices.reserve(count);
  out.normals.reserve(count);
  out.reach = static_cast<float>(options.reach);
  const float x0 = dem.heights->x0, y0 = dem.heights->y0;
  const float x1 = x0 + (dem.width - 1) * dem.dx, y1 = y0 - (dem.height - 1) * dem.dy;
  auto spacing = [&](int i) {
    return static_cast<float>(d[std::min(i + 1, k - 1)] - d[std::max(i - 1, 0)]) * 0.5f;
  };
  // A block of nx x ny vertices at position(i, j), cut into Embree grids
  // that share their edge rows.
  auto add_block = [&](int nx, int ny, auto position) {
    const unsigned start = static_cast<unsigned>(out.vertices.size());
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) out.vertices.push_back(position(i, j));
    add_normals(out, start, nx, ny);
    for (int gy = 0; gy < ny - 1; gy += kMaxGridSide - 1)
      for (int gx = 0; gx < nx - 1; gx += kMaxGridSide - 1)
        out.grids.push_back({start + static_cast<unsigned>(gy * nx + gx), static_cast<unsigned>(nx),
                             static_cast<unsigned short>(std::min(kMaxGridSide, nx - gx)),
                             static_cast<unsigned short>(std::min(kMaxGridSide, ny - gy))});
  };
  auto at = [&](float x, float y, float s) { return Eigen::Vector3f(x, y, height(x, y, s)); };
  const int w = dem.width, h = dem.height;
  add_block(w, k, [&](int c, int j) { return at(x0 + c * dem.dx, y0 + d[j], spacing(j)); });
  add_block(w, k, [&](int c, int j) { return at(x0 + c * dem.dx, y1 - d[j], spacing(j)); });
  add_block(k, h, [&](int i, int r) { return at(x0 - d[i], y0 - r * dem.dy, spacing(i)); });
  add_block(k, h, [&](int i, int r) { return at(x1 + d[i], y0 - r * dem.dy, spacing(i)); });
  for (const float sx : {-1.0f, 1.0f})
    for (const float sy : {-1.0f, 1.0f})
      add_block(k, k, [&](int i, int j) {
        return at(sx < 0 ? x0 - d[i] : x1 + d[i], sy > 0 ? y0 + d[j] : y1 - d[j],
                  std::max(spacing(i), spacing(j)));
      });
  return out;
}

}  // namespace drift::render
