#include "render/atmosphere.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "terrain/bilinear.h"
#include "terrain/error.h"

namespace drift::render {

namespace {

constexpr double kPi = std::numbers::pi;

// Bruneton 2017's tables on 360..830 nm every 10 nm (48 entries):
// ozone absorption cross sections (m^2, Serdyuchenko et al. 2014) and the
// ASTM G-173 extraterrestrial solar spectral irradiance (W m^-2 nm^-1).
constexpr double kOzoneCrossSection[48] = {
    1.18e-27,  2.182e-28, 2.818e-28, 6.636e-28, 1.527e-27, 2.763e-27, 5.52e-27,  8.451e-27,
    1.582e-26, 2.316e-26, 3.669e-26, 4.924e-26, 7.752e-26, 9.016e-26, 1.48e-25,  1.602e-25,
    2.139e-25, 2.755e-25, 3.091e-25, 3.5e-25,   4.266e-25, 4.672e-25, 4.398e-25, 4.701e-25,
    5.019e-25, 4.305e-25, 3.74e-25,  3.215e-25, 2.662e-25, 2.238e-25, 1.852e-25, 1.473e-25,
    1.209e-25, 9.423e-26, 7.455e-26, 6.566e-26, 5.105e-26, 4.15e-26,  4.228e-26, 3.237e-26,
    2.451e-26, 2.801e-26, 2.534e-26, 1.624e-26, 1.465e-26, 2.078e-26, 1.383e-26, 7.105e-27};
constexpr double kSolarIrradiance[48] = {
    1.11776, 1.14259, 1.01249, 1.14716, 1.72765, 1.73054, 1.6887,  1.61253, 1.91198, 2.03474,
    2.02042, 2.02212, 1.93377, 1.95809, 1.91686, 1.8298,  1.8685,  1.8931,  1.85149, 1.8504,
    1.8341,  1.8345,  1.8147,  1.78158, 1.7533,  1.6965,  1.68194, 1.64654, 1.6048,  1.52143,
    1.55622, 1.5113,  1.474,   1.4482,  1.41018, 1.36775, 1.34188, 1.31429, 1.28303, 1.26758,
    1.2367,  1.2082,  1.18737, 1.14683, 1.12362, 1.1058,  1.07124, 1.04992};
// CIE 1931 2-degree colour matching functions (CVRL, ciexyz31) at our bands.
constexpr double kCie[kBands][3] = {{0.0001299, 0.000003917, 0.0006061},
                                    {0.004243, 0.00012, 0.02005},
                                    {0.13438, 0.004, 0.6456},
                                    {0.3362, 0.038, 1.77211},
                                    {0.09564, 0.13902, 0.8129501},
                                    {0.0093, 0.503, 0.1582},
                                    {0.2904, 0.954, 0.0203},
                                    {0.7621, 0.952, 0.0021},
                                    {1.0622, 0.631, 0.0008},
                                    {0.6424, 0.265, 0.00005},
                                    {0.1649, 0.061, 0.0},
                                    {0.0227, 0.00821, 0.0},
                                    {0.002899327, 0.001047, 0.0},
                                    {0.0003323011, 0.00012, 0.0},
                                    {0.00004150994, 0.00001499, 0.0},
                                    {0.000005085868, 0.0000018366, 0.0}};
constexpr double kBandWidthNm = 30.0;

constexpr double kRayleighScaleHeight = 8000.0;
constexpr double kMieScaleHeight = 1200.0;
constexpr double kMieExtinction = 5.328e-3 / kMieScaleHeight;  // Angstrom beta / H, alpha 0
constexpr double kMieSingleScatteringAlbedo = 0.9;
constexpr double kMieG = 0.8;
constexpr double kMaxOzoneDensity = 300.0 * 2.687e20 / 15000.0;  // 300 DU over the tent
constexpr double kTableTop = 60000.0;  // altitude of the tables' top (air above is negligible)

double ozone_cross_section(double nm) {
  const double f = std::clamp((nm - 360.0) / 10.0, 0.0, 47.0);
  const int i = std::min(static_cast<int>(f), 46);
  return kOzoneCrossSection[i] + (f - i) * (kOzoneCrossSection[i + 1] - kOzoneCrossSection[i]);
}
double ozone_density(double h) { return std::max(0.0, 1.0 - std::abs(h - 25000.0) / 15000.0); }

// Each band's Rayleigh coefficient and ozone cross section, worked out once:
// the tables' integrals ask for them millions of times (same values, same bits).
struct BandCoefficients {
  double rayleigh[kBands];
  double ozone[kBands];
};
const BandCoefficients& band_coefficients() {
  static const BandCoefficients c = [] {
    BandCoefficients out{};
    for (int b = 0; b < kBands; ++b) {
      out.rayleigh[b] = Atmosphere::rayleigh_coefficient(Atmosphere::wavelength_nm(b));
      out.ozone[b] = ozone_cross_section(Atmosphere::wavelength_nm(b));
    }
    return out;
  }();
  return c;
}

// Distance from radius r along cosine-zenith mu to the top of the atmosphere,
// and to the ground (negative if the ray misses it).
double distance_to_top(double r, double mu) {
  const double d = r * r * (mu * mu - 1.0) + Atmosphere::kTopRadius * Atmosphere::kTopRadius;
  return std::max(0.0, -r * mu + std::sqrt(std::max(d, 0.0)));
}
double distance_to_ground(double r, double mu) {
  const double d = r * r * (mu * mu - 1.0) + Atmosphere::kBottomRadius * Atmosphere::kBottomRadius;
  if (mu >= 0.0 || d < 0.0) return -1.0;
  return -r * mu - std::sqrt(d);
}

// Table coordinates: altitude with sqrt spacing, mu with u|u| (dense at the horizon).
double altitude_of(int i, int n) {
  const double a = static_cast<double>(i) / (n - 1);
  return kTableTop * a * a;
}
double altitude_index(double h, int n) {
  return std::sqrt(std::clamp(h, 0.0, kTableTop) / kTableTop) * (n - 1);
}
double mu_of(int i, int n) {
  const double u = -1.0 + 2.0 * i / (n - 1);
  return u * std::abs(u);
}
double mu_index(double mu, int n) {
  const double u = std::copysign(std::sqrt(std::abs(std::clamp(mu, -1.0, 1.0))), mu);
  return (u + 1.0) * 0.5 * (n - 1);
}

Spectrum bilinear(const std::vector<Spectrum>& table, int na, int nm, double fa, double fm) {
  const int a0 = std::clamp(static_cast<int>(fa), 0, na - 2);
  const int m0 = std::clamp(static_cast<int>(fm), 0, nm - 2);
  const float ta = static_cast<float>(std::clamp(fa - a0, 0.0, 1.0));
  const float tm = static_cast<float>(std::clamp(fm - m0, 0.0, 1.0));
  Spectrum out{};
  const Spectrum& s00 = table[a0 * nm + m0];
  const Spectrum& s01 = table[a0 * nm + m0 + 1];
  const Spectrum& s10 = table[(a0 + 1) * nm + m0];
  const Spectrum& s11 = table[(a0 + 1) * nm + m0 + 1];
  for (int b = 0; b < kBands; ++b) {
    out[b] = terrain::bilinear_blend(s00[b], s01[b], s10[b], s11[b], tm, ta);
  }
  return out;
}

}  // namespace

float rayleigh_phase(float c) { return 3.0f / (16.0f * static_cast<float>(kPi)) * (1.0f + c * c); }

float mie_phase(float c, float g) {
  // Cornette & Shanks 1992.
  const float g2 = g * g;
  const float k = 3.0f / (8.0f * static_cast<float>(kPi)) * (1.0f - g2) / (2.0f + g2);
  return k * (1.0f + c * c) / std::pow(1.0f + g2 - 2.0f * g * c, 1.5f);
}

double Atmosphere::wavelength_nm(int band) { return 360.0 + 30.0 * band; }

double Atmosphere::aerosol_scale_for_visibility(double km) {
  const double extinction = 3.912 / (km * 1000.0);  // Koschmieder 1924
  const double rayleigh = rayleigh_coefficient(550.0);
  if (!(km > 0.0) || !(extinction > rayleigh)) {
    throw Error("a visibility of " + std::to_string(km) +
                " km is clearer than air without aerosols allows (at most " +
                std::to_string(3.912 / rayleigh / 1000.0) + " km); give a shorter one");
  }
  return (extinction - rayleigh) / kMieExtinction;
}

double Atmosphere::rayleigh_coefficient(double nm) {
  const double um = nm * 1e-3;
  return 1.24062e-6 / (um * um * um * um);  // Bruneton 2017: kRayleigh / lambda^4
}

Spectrum Atmosphere::rayleigh_scattering(double h) const {
  Spectrum s{};
  const double density = std::exp(-std::max(h, 0.0) / kRayleighScaleHeight);
  const BandCoefficients& k = band_coefficients();
  for (int b = 0; b < kBands; ++b) s[b] = static_cast<float>(k.rayleigh[b] * density);
  return s;
}

Spectrum Atmosphere::mie_scattering(double h) const {
  Spectrum s{};
  const double v = kMieExtinction * kMieSingleScatteringAlbedo * parameters_.aerosol_scale *
                   std::exp(-std::max(h, 0.0) / kMieScaleHeight);
  s.fill(static_cast<float>(v));
  return s;
}

Spectrum Atmosphere::extinction(double h) const {
  Spectrum s{};
  const double hh = std::max(h, 0.0);
  const double rayleigh = std::exp(-hh / kRayleighScaleHeight);
  const double mie = kMieExtinction * parameters_.aerosol_scale * std::exp(-hh / kMieScaleHeight);
  const double ozone = kMaxOzoneDensity * ozone_density(hh);
  const BandCoefficients& k = band_coefficients();
  for (int b = 0; b < kBands; ++b)
    s[b] = static_cast<float>(k.rayleigh[b] * rayleigh + mie + k.ozone[b] * ozone);
  return s;
}

// Optical depths from altitude h along mu to the top for n wavelengths given
// by their Rayleigh coefficients and ozone cross sections; the densities are
// evaluated once per step for all of them. Infinite if the ground is in the way.
void Atmosphere::optical_depths(double h, double mu, const double* rayleigh, const double* ozone,
                                int n, double* depth) const {
  const double r = kBottomRadius + std::clamp(h, 0.0, kTableTop);
  if (distance_to_ground(r, mu) >= 0.0) {
    std::fill(depth, depth + n, std::numeric_limits<double>::infinity());
    return;
  }
  const double length = distance_to_top(r, mu);
  const double mie = kMieExtinction * parameters_.aerosol_scale;
  std::fill(depth, depth + n, 0.0);
  // Midpoint rule on t = L s^2: dense where the air is (near the start).
  constexpr int kSteps = 200;
  for (int k = 0; k < kSteps; ++k) {
    const double s0 = static_cast<double>(k) / kSteps, s1 = static_cast<double>(k + 1) / kSteps;
    const double t0 = length * s0 * s0, t1 = length * s1 * s1, tm = 0.5 * (t0 + t1);
    const double hm = std::sqrt(r * r + tm * tm + 2.0 * r * mu * tm) - kBottomRadius;
    const double dt = t1 - t0;
    const double rho_r = std::exp(-hm / kRayleighScaleHeight) * dt;
    const double rho_m = mie * std::exp(-hm / kMieScaleHeight) * dt;
    const double rho_o = kMaxOzoneDensity * ozone_density(hm) * dt;
    for (int i = 0; i < n; ++i) depth[i] += rayleigh[i] * rho_r + rho_m + ozone[i] * rho_o;
  }
}

double Atmosphere::optical_depth_to_space(double nm, double h, double mu) const {
  const double rayleigh = rayleigh_coefficient(nm), ozone = ozone_cross_section(nm);
  double depth = 0.0;
  optical_depths(h, mu, &rayleigh, &ozone, 1, &depth);
  return depth;
}

Spectrum Atmosphere::transmittance_to_space_exact(double h, double mu) const {
  const BandCoefficients& k = band_coefficients();
  double depth[kBands];
  optical_depths(h, mu, k.rayleigh, k.ozone, kBands, depth);
  Spectrum t{};
  for (int b = 0; b < kBands; ++b) t[b] = static_cast<float>(std::exp(-depth[b]));
  return t;
}

Spectrum Atmosphere::transmittance_to_space(double h, double mu) const {
  return bilinear(transmittance_table_, kAltitudes, kMus, altitude_index(h, kAltitudes),
                  mu_index(mu, kMus));
}

Spectrum Atmosphere::multiple_scattering(double h, double mu_sun) const {
  const double fa = std::sqrt(std::clamp(h, 0.0, kTableTop) / kTableTop) * (kMsAltitudes - 1);
  const double fm = (std::clamp(mu_sun, -1.0, 1.0) + 1.0) * 0.5 * (kMsMus - 1);
  return bilinear(ms_table_, kMsAltitudes, kMsMus, fa, fm);
}

Atmosphere::Atmosphere(const AtmosphereParameters& parameters) : parameters_(parameters) {
  init_sun_colour();
  transmittance_table_.resize(static_cast<std::size_t>(kAltitudes) * kMus);
  tbb::parallel_for(0, kAltitudes, [&](int a) {
    for (int m = 0; m < kMus; ++m)
      transmittance_table_[a * kMus + m] =
          transmittance_to_space_exact(altitude_of(a, kAltitudes), mu_of(m, kMus));
  });
  ms_table_.resize(static_cast<std::size_t>(kMsAltitudes) * kMsMus);
  tbb::parallel_for(0, kMsAltitudes, [&](int a) {
    const double fa = static_cast<double>(a) / (kMsAltitudes - 1);
    const double h = kTableTop * fa * fa;
    multiple_scattering_row(h, &ms_table_[static_cast<std::size_t>(a) * kMsMus]);
  });
}

void Atmosphere::init_sun_colour() {
  // Colour: the sun's spectrum per band in linear sRGB (IEC 61966-2-1 matrix),
  // normalised to a top-of-atmosphere luminance of 1.
  double sun_y = 0.0;
  for (int b = 0; b < kBands; ++b) sun_y += kSolarIrradiance[3 * b] * kCie[b][1] * kBandWidthNm;
  Eigen::Matrix3d xyz_to_srgb;
  xyz_to_srgb << 3.2406, -1.5372, -0.4986, -0.9689, 1.8758, 0.0415, 0.0557, -0.2040, 1.0570;
  sun_rgb_total_.setZero();
  for (int b = 0; b < kBands; ++b) {
    const Eigen::Vector3d xyz(kCie[b][0], kCie[b][1], kCie[b][2]);
    sun_band_rgb_[b] =
        (xyz_to_srgb * xyz * (kSolarIrradiance[3 * b] * kBandWidthNm / sun_y)).cast<float>();
    sun_rgb_total_ += sun_band_rgb_[b];
  }
}

namespace {

// Hillaire 2020's sphere of directions and steps along each (below).
constexpr int kMsDirections = 64;
constexpr int kMsSteps = 20;

// One step of a direction's path: where it is and, per band, the path's
// transmittance to it times the scattering there (ts) and the step's
// integrated transmittance (seg). None of it depends on the sun.
struct MsStep {
  Eigen::Vector3d x;
  double rx = 0.0, hx = 0.0;
  std::array<double, kBands> ts{}, seg{};
};
struct MsPath {
  std::array<MsStep, kMsSteps> steps;
  std::array<double, kBands> trans_end{};  // to the ground (or the top)
  Eigen::Vector3d w{0, 0, 1};
  double ground = -1.0;  // distance to the ground, < 0 if the path misses it
};

}  // namespace

void Atmosphere::multiple_scattering_row(double h, Spectrum* row) const {
  // Multiple scattering (Hillaire 2020, eqs. 5-10): at altitude h and sun
  // zenith cosine mu_s, integrate over the sphere of directions the
  // second-order light (isotropic phase) and the transfer f_ms;
  // Psi = L2 / (1 - f_ms). Along each direction from radius r to the ground
  // or the top: the sun's light scattered once towards the start (l2) and
  // the share scattered at all (f). The paths and f do not depend on the
  // sun, so they are traced once for the row's kMsMus sun angles (the same
  // sums in the same order as tracing them for each: same bits, a 20th of
  // the exponentials).
  const double r = kBottomRadius + h;
  const Eigen::Vector3d origin(0.0, 0.0, r);
  std::vector<MsPath> paths(kMsDirections);
  std::array<double, kBands> f{};
  for (int d = 0; d < kMsDirections; ++d) {
    // Fibonacci sphere: even directions.
    const double z = 1.0 - 2.0 * (d + 0.5) / kMsDirections;
    const double phi = d * kPi * (3.0 - std::sqrt(5.0));
    const double s = std::sqrt(1.0 - z * z);
    MsPath& path = paths[d];
    path.w = Eigen::Vector3d(s * std::cos(phi), s * std::sin(phi), z);
    path.ground = distance_to_ground(r, path.w.z());
    const double length = path.ground >= 0.0 ? path.ground : distance_to_top(r, path.w.z());
    const double dt = length / kMsSteps;
    std::array<double, kBands> trans;
    trans.fill(1.0);
    for (int k = 0; k < kMsSteps; ++k) {
      MsStep& step = path.steps[k];
      step.x = origin + path.w * ((k + 0.5) * dt);
      step.rx = step.x.norm(), step.hx = step.rx - kBottomRadius;
      const Spectrum ext = extinction(step.hx);
      const Spectrum sr = rayleigh_scattering(step.hx), sm = mie_scattering(step.hx);
      for (int b = 0; b < kBands; ++b) {
        const double sigma_s = sr[b] + sm[b];
        const double step_t = std::exp(-ext[b] * dt);
        step.seg[b] = (1.0 - step_t) / std::max<double>(ext[b], 1e-12);
        step.ts[b] = trans[b] * sigma_s;
        f[b] += step.ts[b] * step.seg[b];
        trans[b] *= step_t;
      }
    }
    path.trans_end = trans;
  }
  for (int m = 0; m < kMsMus; ++m) {
    const double mu_s = -1.0 + 2.0 * m / (kMsMus - 1);
    const Eigen::Vector3d sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
    std::array<double, kBands> l2{};
    for (const MsPath& path : paths) {
      for (const MsStep& step : path.steps) {
        const Spectrum sun_t = transmittance_to_space(step.hx, step.x.dot(sun) / step.rx);
        for (int b = 0; b < kBands; ++b) l2[b] += step.ts[b] * sun_t[b] / (4.0 * kPi) * step.seg[b];
      }
      if (path.ground >= 0.0) {  // Lambertian ground lit by the sun
        const Eigen::Vector3d g = origin + path.w * path.ground;
        const double mu_g = g.dot(sun) / g.norm();
        const Spectrum sun_t = transmittance_to_space(0.0, mu_g);
        for (int b = 0; b < kBands; ++b)
          l2[b] +=
              path.trans_end[b] * sun_t[b] * std::max(mu_g, 0.0) * parameters_.ground_albedo / kPi;
      }
    }
    for (int b = 0; b < kBands; ++b) {
      const double l2_avg = l2[b] / kMsDirections, f_avg = f[b] / kMsDirections;
      row[m][b] = static_cast<float>(l2_avg / (1.0 - std::min(f_avg, 0.99)));
    }
  }
}

Spectrum Atmosphere::in_scattering(double h0, const Eigen::Vector3d& view, double length,
                                   const Eigen::Vector3d& sun, int steps,
                                   Spectrum* transmittance) const {
  const double r0 = kBottomRadius + std::max(h0, 0.0);
  const double mu = view.z();
  const double ground = distance_to_ground(r0, mu);
  const double limit = ground >= 0.0 ? ground : distance_to_top(r0, mu);
  const double total = std::min(length, limit);
  const double dt = total / steps;
  const float nu = static_cast<float>(view.dot(sun));
  const float pr = rayleigh_phase(nu), pm = mie_phase(nu, static_cast<float>(kMieG));
  const Eigen::Vector3d origin(0.0, 0.0, r0);
  Spectrum radiance{}, trans;
  trans.fill(1.0f);
  for (int k = 0; k < steps; ++k) {
    const Eigen::Vector3d x = origin + view * ((k + 0.5) * dt);
    const double rx = x.norm(), hx = rx - kBottomRadius, mu_s = x.dot(sun) / rx;
    const Spectrum ext = extinction(hx), sr = rayleigh_scattering(hx), sm = mie_scattering(hx);
    const Spectrum sun_t = transmittance_to_space(hx, mu_s);
    const Spectrum psi = multiple_scattering(hx, mu_s);
    for (int b = 0; b < kBands; ++b) {
      const float source = (sr[b] * pr + sm[b] * pm) * sun_t[b] + (sr[b] + sm[b]) * psi[b];
      const float step_t = std::exp(-ext[b] * static_cast<float>(dt));
      // Hillaire's energy-conserving integration of the source over the step.
      radiance[b] += trans[b] * source * (1.0f - step_t) / std::max(ext[b], 1e-12f);
      trans[b] *= step_t;
    }
  }
  if (transmittance) *transmittance = trans;
  return radiance;
}

Spectrum Atmosphere::ground_radiance(double h0, const Eigen::Vector3d& view,
                                     const Eigen::Vector3d& sun) const {
  Spectrum out{};
  const double r0 = kBottomRadius + std::max(h0, 0.0);
  const double d = distance_to_ground(r0, view.z());
  if (d < 0.0) return out;
  Spectrum t;
  in_scattering(h0, view, d, sun, 16, &t);
  const Eigen::Vector3d g = Eigen::Vector3d(0.0, 0.0, r0) + view * d;
  const double mu_s = g.dot(sun) / g.norm();
  if (mu_s <= 0.0) return out;
  const Spectrum sun_t = transmittance_to_space(0.0, mu_s);
  for (int b = 0; b < kBands; ++b)
    out[b] = static_cast<float>(t[b] * sun_t[b] * mu_s * parameters_.ground_albedo / kPi);
  return out;
}

Eigen::Vector3f Atmosphere::radiance_to_rgb(const Spectrum& relative) const {
  Eigen::Vector3f rgb = Eigen::Vector3f::Zero();
  for (int b = 0; b < kBands; ++b) rgb += sun_band_rgb_[b] * relative[b];
  return rgb.cwiseMax(0.0f);
}

Eigen::Vector3f Atmosphere::sun_rgb(const Spectrum& transmittance) const {
  return radiance_to_rgb(transmittance);
}

Eigen::Vector3f Atmosphere::transmittance_rgb(const Spectrum& transmittance) const {
  return sun_rgb(transmittance).cwiseQuotient(sun_rgb_total_).cwiseMax(0.0f).cwiseMin(1.0f);
}

}  // namespace drift::render
