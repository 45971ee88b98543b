// The atmosphere as one render sees it (render/atmosphere.h), precomputed for
// its camera and sun: the sky's radiance in every direction (Hillaire's
// sky-view table), aerial perspective from the camera to any distance in any
// direction (a direction x distance table), the sun's transmitted colour at
// any altitude, and the air along short path segments between surfaces.
// All results are linear sRGB in render units: the sun's top-of-atmosphere
// luminance is `sun_scale`.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "render/atmosphere.h"

namespace drift::render {

struct AirSegment {
  Eigen::Vector3f inscatter{0, 0, 0};
  Eigen::Vector3f transmittance{1, 1, 1};
};

class PhysicalSky {
 public:
  // camera_altitude in metres above sea level; sun: unit direction towards
  // the sun (x east, y north, z up); max_distance: the farthest surface a
  // camera ray can reach (the aerial-perspective table's depth).
  PhysicalSky(const Atmosphere& atmosphere, double camera_altitude, const Eigen::Vector3d& sun,
              float sun_scale, double max_distance);

  // Radiance of the sky (sun disc excluded) seen from the camera.
  Eigen::Vector3f sky(const Eigen::Vector3f& dir) const;
  // In-scattered light and transmittance from the camera along dir to distance.
  AirSegment from_camera(const Eigen::Vector3f& dir, float distance) const;
  // The same for a short segment anywhere (homogeneous air at its mid altitude).
  AirSegment segment(float mid_altitude, const Eigen::Vector3f& dir, float length) const;
  // The part of segment()'s in-scatter that is the sun's single scattering:
  // what the air of the segment stops sending when the terrain hides the sun
  // from it (light shafts, render/light_shafts.h).
  Eigen::Vector3f sun_single_scattering(float mid_altitude, const Eigen::Vector3f& dir,
                                        float length) const;
  // Irradiance on a level surface at the camera from the sun and the whole
  // sky above the horizon (the colour of the day's light; white balance).
  Eigen::Vector3f level_irradiance() const;
  // Irradiance of the sun at an altitude, after the air above (on a surface
  // facing it).
  Eigen::Vector3f sun_irradiance(float altitude) const;

 private:
  static constexpr int kSkyElevations = 64, kSkyAzimuths = 64;
  static constexpr int kApElevations = 32, kApAzimuths = 32, kApSlices = 32;
  static constexpr int kAltitudes = 96;
  static constexpr float kMaxAltitude = 9000.0f;

  const Atmosphere& atmosphere_;
  Eigen::Vector3d sun_;
  float sun_scale_;
  double camera_altitude_, max_distance_;
  float sun_azimuth_;  // atan2(x, y) of the sun, once (every sky lookup needs it)
  std::vector<Eigen::Vector3f> sky_table_;
  std::vector<AirSegment> ap_table_;
  // Per altitude: spectra for short segments and the sun's colour.
  std::vector<Spectrum> extinction_, scattering_rayleigh_, scattering_mie_, sun_transmittance_,
      multiple_;
  std::vector<Eigen::Vector3f> sun_rgb_;

  // Direction <-> table coordinates (elevation dense at the horizon,
  // azimuth relative to the sun's, folded to [0, pi]).
  void coordinates(const Eigen::Vector3f& dir, int elevations, int azimuths, float& fe,
                   float& fa) const;
  Eigen::Vector3d direction(int e, int a, int elevations, int azimuths) const;
  float altitude_index(float altitude) const;
  // In-scatter (and optionally transmittance) of a homogeneous segment at
  // altitude table index i: the sun's single scattering, plus the multiple
  // scattering when `multiple`.
  Spectrum segment_inscatter(int i, const Eigen::Vector3f& dir, float length, bool multiple,
                             Spectrum* transmittance) const;
};

}  // namespace drift::render
