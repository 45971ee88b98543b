// A physically based Earth atmosphere, computed spectrally (16 bands from 360
// to 810 nm) and turned into linear sRGB through the CIE 1931 colour matching
// functions, in the manner of Hillaire 2020 ("A scalable and production ready
// sky and atmosphere rendering technique") with the parameters of Bruneton
// 2017 ("precomputed_atmospheric_scattering", its reference values):
//   Rayleigh scattering 1.24062e-6 / lambda^4 (lambda in um), scale height 8 km;
//   Mie extinction 4.44e-6 /m (Angstrom beta 5.328e-3 over 1.2 km), single-
//   scattering albedo 0.9, Cornette-Shanks phase g = 0.8, scale height 1.2 km;
//   ozone: 300 Dobson units in a tent from 10 to 40 km (peak at 25 km),
//   absorption cross sections of Serdyuchenko et al. 2014 as tabulated there;
//   top-of-atmosphere solar spectrum ASTM G-173 (as tabulated there);
//   planet radius 6360 km, atmosphere top 6420 km, ground albedo 0.3.
// Multiple scattering follows Hillaire's isotropic approximation (his
// section 5.5, eqs. 5-10): a table Psi_ms(altitude, sun zenith).
//
// Lengths in metres; altitudes above sea level.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

namespace drift::render {

constexpr int kBands = 16;
using Spectrum = std::array<float, kBands>;

struct AtmosphereParameters {
  double aerosol_scale = 1.0;  // multiplies the aerosol (Mie) density: haze
  double ground_albedo = 0.3;
};

class Atmosphere {
 public:
  explicit Atmosphere(const AtmosphereParameters& parameters = {});

  static double wavelength_nm(int band);  // 360 + 30 band

  // Rayleigh scattering at sea level (per metre) at any wavelength.
  static double rayleigh_coefficient(double nm);
  // The aerosol_scale that gives a meteorological visibility of `km` at sea
  // level: Koschmieder's law, extinction at 550 nm = 3.912 / V (a black
  // object at distance V keeps 2 % contrast). Throws drift::Error when V is
  // clearer than air without aerosols allows (about 288 km).
  static double aerosol_scale_for_visibility(double km);
  // Optical depth at one wavelength from an altitude along cosine-zenith mu to
  // the top of the atmosphere (infinite if the ray meets the ground).
  double optical_depth_to_space(double nm, double altitude, double mu) const;

  // Media at an altitude (m), per metre.
  Spectrum rayleigh_scattering(double altitude) const;
  Spectrum mie_scattering(double altitude) const;
  Spectrum extinction(double altitude) const;

  // Transmittance from an altitude along a direction of cosine-zenith mu to
  // the top of the atmosphere (0 if the ray meets the ground): a table,
  // bilinear in (altitude, mu).
  Spectrum transmittance_to_space(double altitude, double mu) const;
  // The same by direct integration (reference for tests and table building).
  Spectrum transmittance_to_space_exact(double altitude, double mu) const;

  // Hillaire's multiple-scattering transfer Psi_ms for unit solar irradiance.
  Spectrum multiple_scattering(double altitude, double mu_sun) const;

  // Radiance scattered towards the observer along a ray from altitude h0 with
  // unit direction `view` (z up, local frame at the ray's start) over `length`
  // metres (to the ground or the top if longer), for unit solar irradiance
  // from direction `sun`; `transmittance` receives the ray's transmittance.
  // `steps` ray-marching steps. Earth's curvature is included.
  Spectrum in_scattering(double h0, const Eigen::Vector3d& view, double length,
                         const Eigen::Vector3d& sun, int steps, Spectrum* transmittance) const;

  // Spectra -> linear sRGB. `radiance_to_rgb` converts a spectral radiance in
  // units of the solar spectral irradiance (what in_scattering returns) with
  // the sun's spectrum applied; `sun_rgb` is the sun's colour after a spectral
  // transmittance; `transmittance_rgb` reduces a spectral transmittance to the
  // three channels (weighted by sunlight's response in each).
  Eigen::Vector3f radiance_to_rgb(const Spectrum& relative_radiance) const;
  Eigen::Vector3f sun_rgb(const Spectrum& transmittance) const;
  Eigen::Vector3f transmittance_rgb(const Spectrum& transmittance) const;

  // Radiance (relative to the solar irradiance) of the Lambertian ground seen
  // from altitude h0 along `view` where the ray meets the planet, including
  // the air's transmittance to it; zero where the ray misses the ground.
  Spectrum ground_radiance(double h0, const Eigen::Vector3d& view,
                           const Eigen::Vector3d& sun) const;

  static constexpr double kBottomRadius = 6360e3;
  static constexpr double kTopRadius = 6420e3;

 private:
  // The constructor's steps: the sun's colour per band, and one altitude's
  // row of the multiple-scattering table (kMsMus entries from `row` on).
  void init_sun_colour();
  void multiple_scattering_row(double altitude, Spectrum* row) const;
  void optical_depths(double h, double mu, const double* rayleigh, const double* ozone, int n,
                      double* depth) const;

  AtmosphereParameters parameters_;
  // Tables over altitude [0, 60 km] (sqrt spacing) and mu in [-1, 1].
  static constexpr int kAltitudes = 64, kMus = 128, kMsMus = 32, kMsAltitudes = 32;
  std::vector<Spectrum> transmittance_table_;  // kAltitudes x kMus
  std::vector<Spectrum> ms_table_;             // kMsAltitudes x kMsMus
  // Linear sRGB per band of the sun's spectrum (and of a flat spectrum), with
  // the luminance of the top-of-atmosphere sun normalised to 1.
  std::array<Eigen::Vector3f, kBands> sun_band_rgb_;
  Eigen::Vector3f sun_rgb_total_;
};

// Phase functions: Rayleigh and Cornette-Shanks (Mie), per steradian.
float rayleigh_phase(float cos_theta);
float mie_phase(float cos_theta, float g);

}  // namespace drift::render
