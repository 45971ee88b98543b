// The sky as an importance-sampled environment light: its radiance tabulated
// once per render on a latitude-longitude grid over the whole sphere, and a
// piecewise-constant 2D distribution over that grid (marginal density of the
// rows, conditional density of the cells in each row), after Pharr, Jakob &
// Humphreys, PBRT 3rd ed., sections 13.6.7 ("Piecewise-constant 2D
// distributions") and 14.2.4 ("Infinite area lights"). The integrator samples
// it for next-event estimation at every surface and weighs those samples
// against BSDF-sampled rays that escape to the sky with the power heuristic
// (Veach 1997, section 9.2), so each direction is counted once.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

namespace drift::render {

// A piecewise-constant density on [0, 1) with `f.size()` equal cells
// (PBRT 3, 13.3.1).
class Distribution1D {
 public:
  explicit Distribution1D(std::vector<float> f);
  // A position in [0, 1) with density pdf(cell) (its cell in `cell`).
  float sample(float u, float& pdf, int& cell) const;
  // Density of cell i on [0, 1); 0 for an all-zero function.
  float pdf(int i) const { return integral_ > 0.0f ? f_[i] / integral_ : 0.0f; }
  float integral() const { return integral_; }  // mean of f over [0, 1)
  int size() const { return static_cast<int>(f_.size()); }

 private:
  std::vector<float> f_, cdf_;
  // Guide table (Chen & Wu's cutpoint method; Devroye 1986, "Non-Uniform
  // Random Variate Generation", sec. III.2.4): guide_[g] is the first cdf
  // index above g / size, so sample() searches a few entries, not all, with
  // the same result as a search of the whole table.
  std::vector<int> guide_;
  float integral_ = 0.0f;
};

class SkySampler {
 public:
  // Tabulates the luminance of `radiance` (linear RGB, by unit direction, z
  // up) at the centres of rows x columns cells of polar angle theta (from the
  // zenith) and azimuth phi (from +x towards +y).
  SkySampler(const std::function<Eigen::Vector3f(const Eigen::Vector3f&)>& radiance, int rows = 64,
             int columns = 128);

  struct Sample {
    Eigen::Vector3f dir{0, 0, 1};
    float pdf = 0.0f;  // per steradian
  };
  // A direction with density roughly proportional to the sky's luminance;
  // false for a black sky.
  bool sample(float u1, float u2, Sample& s) const;
  // The density (per steradian) with which sample() returns `dir`.
  float pdf(const Eigen::Vector3f& dir) const;

 private:
  int rows_, columns_;
  std::vector<Distribution1D> conditional_;  // over phi, one per row
  Distribution1D marginal_;                  // over theta
};

// The power heuristic with beta = 2 for one sample from each of two
// strategies (Veach 1997, eq. 9.13): the weight of the one with density pa.
inline float power_heuristic(float pa, float pb) {
  const float a = pa * pa, b = pb * pb;
  return a > 0.0f ? a / (a + b) : 0.0f;
}

}  // namespace drift::render
