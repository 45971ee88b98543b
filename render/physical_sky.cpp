#include "render/physical_sky.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "render/fast_math.h"
#include "terrain/bilinear.h"

namespace drift::render {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr float kMieG = 0.8f;

// Elevation l in [-pi/2, pi/2] <-> v in [0, 1], dense at the horizon
// (Hillaire 2020, sec. 5.3).
float elevation_to_v(float l) {
  const float h = static_cast<float>(kPi / 2);
  return 0.5f + 0.5f * std::copysign(std::sqrt(std::abs(l) / h), l);
}
double v_to_elevation(double v) {
  const double s = 2.0 * (v - 0.5);
  return std::copysign(s * s, s) * kPi / 2;
}

template <class T>
T lerp(const T& a, const T& b, float t) {
  return a * (1.0f - t) + b * t;
}

}  // namespace

void PhysicalSky::coordinates(const Eigen::Vector3f& dir, int elevations, int azimuths, float& fe,
                              float& fa) const {
  const float l = fast_asin(dir.z());
  fe = elevation_to_v(l) * (elevations - 1);
  // Azimuth relative to the sun's, folded (the sky is symmetric about the
  // sun's vertical plane).
  // Both angles lie in [-pi, pi], so one turn added or taken brings the
  // difference into [-pi, pi] (std::remainder was a libm call a lookup).
  constexpr float pi = static_cast<float>(kPi), turn = 2.0f * pi;
  float rel = fast_atan2(dir.x(), dir.y()) - sun_azimuth_;
  if (rel > pi) rel -= turn;
  if (rel < -pi) rel += turn;
  rel = std::min(std::abs(rel), pi);
  fa = rel / static_cast<float>(kPi) * (azimuths - 1);
}

Eigen::Vector3d PhysicalSky::direction(int e, int a, int elevations, int azimuths) const {
  const double l = v_to_elevation(static_cast<double>(e) / (elevations - 1));
  const double sun_az = std::atan2(sun_.x(), sun_.y());
  const double az = sun_az + kPi * a / (azimuths - 1);
  return {std::sin(az) * std::cos(l), std::cos(az) * std::cos(l), std::sin(l)};
}

float PhysicalSky::altitude_index(float altitude) const {
  return std::clamp(altitude / kMaxAltitude, 0.0f, 1.0f) * (kAltitudes - 1);
}

PhysicalSky::PhysicalSky(const Atmosphere& atmosphere, double camera_altitude,
                         const Eigen::Vector3d& sun, float sun_scale, double max_distance)
    : atmosphere_(atmosphere),
      sun_(sun.normalized()),
      sun_scale_(sun_scale),
      camera_altitude_(std::max(camera_altitude, 0.0)),
      max_distance_(std::max(max_distance, 1.0)),
      sun_azimuth_(static_cast<float>(std::atan2(sun_.x(), sun_.y()))) {
  // Sky view (background and bounce rays that leave the scene).
  sky_table_.resize(static_cast<std::size_t>(kSkyElevations) * kSkyAzimuths);
  tbb::parallel_for(0, kSkyElevations, [&](int e) {
    for (int a = 0; a < kSkyAzimuths; ++a) {
      const Eigen::Vector3d d = direction(e, a, kSkyElevations, kSkyAzimuths);
      Spectrum t;
      Spectrum l = atmosphere_.in_scattering(camera_altitude_, d, 1e9, sun_, 32, &t);
      // Below the horizon: the distant ground beyond the scene, through the air.
      const Spectrum ground = atmosphere_.ground_radiance(camera_altitude_, d, sun_);
      for (int b = 0; b < kBands; ++b) l[b] += ground[b];
      sky_table_[e * kSkyAzimuths + a] = atmosphere_.radiance_to_rgb(l) * sun_scale_;
    }
  });
  // Aerial perspective from the camera: slices at distances (s / n)^2 * max.
  ap_table_.resize(static_cast<std::size_t>(kApElevations) * kApAzimuths * kApSlices);
  tbb::parallel_for(0, kApElevations, [&](int e) {
    for (int a = 0; a < kApAzimuths; ++a) {
      const Eigen::Vector3d d = direction(e, a, kApElevations, kApAzimuths);
      for (int s = 0; s < kApSlices; ++s) {
        const double f = static_cast<double>(s + 1) / kApSlices;
        Spectrum t;
        const Spectrum l = atmosphere_.in_scattering(camera_altitude_, d, max_distance_ * f * f,
                                                     sun_, 6 + s / 4, &t);
        AirSegment& out = ap_table_[(e * kApAzimuths + a) * kApSlices + s];
        out.inscatter = atmosphere_.radiance_to_rgb(l) * sun_scale_;
        out.transmittance = atmosphere_.transmittance_rgb(t);
      }
    }
  });
  // Per altitude: media and the sun.
  for (int i = 0; i < kAltitudes; ++i) {
    const double h = kMaxAltitude * i / (kAltitudes - 1);
    extinction_.push_back(atmosphere_.extinction(h));
    scattering_rayleigh_.push_back(atmosphere_.rayleigh_scattering(h));
    scattering_mie_.push_back(atmosphere_.mie_scattering(h));
    sun_transmittance_.push_back(atmosphere_.transmittance_to_space(h, sun_.z()));
    multiple_.push_back(atmosphere_.multiple_scattering(h, sun_.z()));
    sun_rgb_.push_back(atmosphere_.sun_rgb(sun_transmittance_.back()) * sun_scale_);
  }
}

Eigen::Vector3f PhysicalSky::sky(const Eigen::Vector3f& dir) const {
  float fe, fa;
  coordinates(dir, kSkyElevations, kSkyAzimuths, fe, fa);
  const int e0 = std::clamp(static_cast<int>(fe), 0, kSkyElevations - 2);
  const int a0 = std::clamp(static_cast<int>(fa), 0, kSkyAzimuths - 2);
  const float te = std::clamp(fe - e0, 0.0f, 1.0f), ta = std::clamp(fa - a0, 0.0f, 1.0f);
  auto at = [&](int e, int a) { return sky_table_[e * kSkyAzimuths + a]; };
  return terrain::bilinear_blend(at(e0, a0), at(e0, a0 + 1), at(e0 + 1, a0), at(e0 + 1, a0 + 1), ta,
                                 te);
}

AirSegment PhysicalSky::from_camera(const Eigen::Vector3f& dir, float distance) const {
  float fe, fa;
  coordinates(dir, kApElevations, kApAzimuths, fe, fa);
  const int e0 = std::clamp(static_cast<int>(fe), 0, kApElevations - 2);
  const int a0 = std::clamp(static_cast<int>(fa), 0, kApAzimuths - 2);
  const float te = std::clamp(fe - e0, 0.0f, 1.0f), ta = std::clamp(fa - a0, 0.0f, 1.0f);
  // Slice s holds distance ((s + 1) / n)^2 max; before slice 0 the air is empty.
  const float fs =
      std::sqrt(std::clamp(distance / static_cast<float>(max_distance_), 0.0f, 1.0f)) * kApSlices -
      1.0f;
  auto slice = [&](int e, int a) {
    auto value = [&](int s) {
      if (s < 0) return AirSegment{};
      return ap_table_[(e * kApAzimuths + a) * kApSlices + std::min(s, kApSlices - 1)];
    };
    const int s0 = static_cast<int>(std::floor(fs));
    const float ts = fs - static_cast<float>(s0);
    const AirSegment a0s = value(s0), a1s = value(s0 + 1);
    return AirSegment{lerp(a0s.inscatter, a1s.inscatter, ts),
                      lerp(a0s.transmittance, a1s.transmittance, ts)};
  };
  auto mix = [](const AirSegment& p, const AirSegment& q, float t) {
    return AirSegment{lerp(p.inscatter, q.inscatter, t), lerp(p.transmittance, q.transmittance, t)};
  };
  return mix(mix(slice(e0, a0), slice(e0, a0 + 1), ta),
             mix(slice(e0 + 1, a0), slice(e0 + 1, a0 + 1), ta), te);
}

Spectrum PhysicalSky::segment_inscatter(int i, const Eigen::Vector3f& dir, float length,
                                        bool multiple, Spectrum* transmittance) const {
  const Spectrum& ext = extinction_[i];
  const Spectrum& sr = scattering_rayleigh_[i];
  const Spectrum& sm = scattering_mie_[i];
  const Spectrum& sun_t = sun_transmittance_[i];
  const Spectrum& psi = multiple_[i];
  const float nu = dir.dot(sun_.cast<float>());
  const float pr = rayleigh_phase(nu), pm = mie_phase(nu, kMieG);
  Spectrum l{};
  for (int b = 0; b < kBands; ++b) {
    const float t = std::exp(-ext[b] * length);
    if (transmittance) (*transmittance)[b] = t;
    float source = (sr[b] * pr + sm[b] * pm) * sun_t[b];
    if (multiple) source += (sr[b] + sm[b]) * psi[b];
    // The source integrated over the segment, each point seen through the
    // air before it: source (1 - T) / extinction.
    l[b] = source * (1.0f - t) / std::max(ext[b], 1e-12f);
  }
  return l;
}

AirSegment PhysicalSky::segment(float mid_altitude, const Eigen::Vector3f& dir,
                                float length) const {
  const int i = static_cast<int>(std::lround(altitude_index(mid_altitude)));
  Spectrum t{};
  const Spectrum l = segment_inscatter(i, dir, length, true, &t);
  return {atmosphere_.radiance_to_rgb(l) * sun_scale_, atmosphere_.transmittance_rgb(t)};
}

Eigen::Vector3f PhysicalSky::sun_single_scattering(float mid_altitude, const Eigen::Vector3f& dir,
                                                   float length) const {
  const int i = static_cast<int>(std::lround(altitude_index(mid_altitude)));
  return atmosphere_.radiance_to_rgb(segment_inscatter(i, dir, length, false, nullptr)) *
         sun_scale_;
}

Eigen::Vector3f PhysicalSky::level_irradiance() const {
  // E = E_sun sin(elevation) + integral of L cos(theta) over the upper
  // hemisphere; with mu = cos(theta), d(omega) cos(theta) = mu d(mu) d(phi):
  // the midpoint rule on a 64 x 128 (mu, phi) grid.
  constexpr int kMu = 64, kPhi = 128;
  Eigen::Vector3f sky_part(0, 0, 0);
  for (int i = 0; i < kMu; ++i) {
    const double mu = (i + 0.5) / kMu, sin_theta = std::sqrt(1.0 - mu * mu);
    for (int j = 0; j < kPhi; ++j) {
      const double phi = 2.0 * kPi * (j + 0.5) / kPhi;
      const Eigen::Vector3f dir(static_cast<float>(sin_theta * std::cos(phi)),
                                static_cast<float>(sin_theta * std::sin(phi)),
                                static_cast<float>(mu));
      sky_part += sky(dir) * static_cast<float>(mu);
    }
  }
  sky_part *= static_cast<float>(2.0 * kPi / (kMu * kPhi));  // d(mu) d(phi)
  const float sun_part = static_cast<float>(std::max(sun_.z(), 0.0));
  return sky_part + sun_irradiance(static_cast<float>(camera_altitude_)) * sun_part;
}

Eigen::Vector3f PhysicalSky::sun_irradiance(float altitude) const {
  const float f = altitude_index(altitude);
  const int i0 = std::min(static_cast<int>(f), kAltitudes - 2);
  return lerp(sun_rgb_[i0], sun_rgb_[i0 + 1], std::clamp(f - i0, 0.0f, 1.0f));
}

}  // namespace drift::render
