// A cloud layer (issue 23, item 5): a thin shell of cloud at one altitude
// above the curved Earth, its vertical optical depth a deterministic field of
// procedural octaves (render/procedural_noise.h) thresholded to the asked
// coverage. Rays that cross it see the cloud's light and lose what is behind
// it by its transmittance; the sun's shadow rays lose it too, so clouds shade
// the ground under them and nothing else.
//
// The cloud's light, per crossing (cloud_look):
// - the sun, at the layer's altitude through the same atmosphere (its colour
//   reddens at a low sun), scattered by a plane-parallel slab: multiple
//   scattering as the conservative-scattering Eddington two-stream slab
//   (Shettle & Weinman 1970, J. Atmos. Sci. 27, 1048; Liou 2002, "An
//   Introduction to Atmospheric Radiation", sec. 6.5), reflected to the sun's
//   side and transmitted diffusely to the other, plus the single scattering's
//   departure from isotropic under a two-term Henyey-Greenstein phase
//   function (Henyey & Greenstein 1941, ApJ 93, 70), which gives the bright
//   rims of thin cloud towards the sun;
// - the sky from above and the ground from below, through the same slab;
// - a 2.5-D cloud: each column's top stands thickness x tau / density above
//   the layer's base, so seen from above the sun falls on sloping tops
//   (sunward flanks bright, lee sides darker), and the sun's ray into a
//   column is marched over its neighbours towards the sun: where their tops
//   stand higher it runs through them (self-shadowing);
// - beneath the layer the air receives less sun: its in-scattering is
//   scaled by the layer's mean transmittance towards the sun (the ground's
//   own cloud shadows are exact, per point); and where the layer lies below
//   the peaks, the terrain's shadow falls on it (render/path_tracer.cpp).
// The field is filtered by the ray's footprint: octaves finer than it are
// dropped and the threshold of what they carried is smoothed by their
// variance (the expected optical depth under Gaussian octaves), so distant
// cloud keeps its mean and does not shimmer. A ray meeting the layer at
// cosine mu to its vertical covers width / mu of it along its direction:
// the filter takes that long axis (grazing_footprint), so cloud near the
// horizon is smooth instead of streaked (an isotropic filter's trade:
// blurred across rather than aliased along).
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace drift::render {

struct CloudOptions {
  bool enabled = false;
  double altitude = 4500.0;  // metres above sea level of the layer's middle
  double thickness = 400.0;  // metres (the self-shadowing's reach)
  double coverage = 0.4;     // fraction of the sky's area under cloud, [0, 1]
  double density = 12.0;     // vertical optical depth where the cloud is thickest
  double scale = 2500.0;     // metres: the wavelength of the largest octave
  std::uint64_t seed = 1;
};

// Where a ray crosses the layer.
struct CloudCrossing {
  float distance = 0.0f;
  Eigen::Vector3f point{0, 0, 0};  // local coordinates
  Eigen::Vector3f up{0, 0, 1};     // the local vertical there (Earth's curvature)
};

// The layer over a footprint: the share of it under cloud and the
// (vertical) optical depth of that cloudy share.
struct CloudSample {
  float cover = 0.0f;
  float tau = 0.0f;
  float mean() const { return cover * tau; }
};

class CloudLayer {
 public:
  // `origin`: CRS coordinates of local (0, 0, 0) (z: metres above sea level),
  // so that the clouds stay where they are in the world.
  CloudLayer(const CloudOptions& options, const Eigen::Vector3d& origin);

  const CloudOptions& options() const { return options_; }
  // Vertical optical depth at local (x, y) for a footprint (metres; 0: every
  // octave), and with `gradient` its gradient per metre in x, y.
  float optical_depth(double x, double y, double footprint,
                      Eigen::Vector2f* gradient = nullptr) const;
  // The footprint's cloudy share and its optical depth (optical_depth is
  // their product, the mean).
  CloudSample covered(double x, double y, double footprint,
                      Eigen::Vector2f* gradient = nullptr) const;
  // The 2.5-D cloud: a column of optical depth tau stands this high above the
  // layer's base (thickness x tau / density: the densest cores the thickest).
  float top_height(float tau) const;
  // What reaches the top of the column at `point` (optical depth tau) of the
  // sun's direct light after the neighbouring columns it passes through on
  // its way in (1: none in the way); `up` the local vertical.
  float sun_shadow(const Eigen::Vector3f& point, const Eigen::Vector3f& up,
                   const Eigen::Vector3f& sun_dir, float tau, float footprint) const;
  // The layer's direct transmittance towards the sun averaged over the
  // ground (its mean shadow): what the air beneath it keeps of the sun.
  float mean_sun_transmittance(const Eigen::Vector3f& sun_dir) const;
  // The first crossing of the ray within (0, max_distance); false if none.
  bool cross(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float max_distance,
             CloudCrossing& crossing) const;
  // Direct transmittance of the layer along `dir` from `p` (1 when the ray
  // does not cross it), for a footprint widening by `spread` per metre.
  float transmittance(const Eigen::Vector3f& p, const Eigen::Vector3f& dir, float width,
                      float spread) const;
  // The farthest a ray from local height z can meet the layer (metres).
  double horizon_distance(double z) const;
  // The noise level above which there is cloud (the coverage's quantile).
  float threshold() const { return threshold_; }

 private:
  float field(double x, double y, double footprint, float& lost_std,
              Eigen::Vector2f* gradient) const;

  CloudOptions options_;
  Eigen::Vector3d origin_;
  double centre_z_, radius_;  // the Earth's centre (local z) and the layer's radius
  float threshold_ = 0.0f, ramp_ = 1.0f;
};

// The light that reaches the layer: the sun's irradiance at its altitude
// (facing the sun) and direction, and the diffuse irradiance on a level
// surface from the sky above and from the ground below.
struct CloudLight {
  Eigen::Vector3f sun{0, 0, 0};
  Eigen::Vector3f sun_dir{0, 0, 1};
  Eigen::Vector3f sky_down{0, 0, 0};
  Eigen::Vector3f ground_up{0, 0, 0};
};

// What a ray crossing the layer sees: the cloud's own radiance towards the
// ray's origin and the fraction of what lies behind that passes.
struct CloudLook {
  Eigen::Vector3f radiance{0, 0, 0};
  float transmittance = 1.0f;
};

// The footprint on the layer of a ray `width` wide meeting it at cosine mu
// to its vertical: the long axis of its ellipse, width / mu (mu >= 0.02).
float grazing_footprint(float width, float mu);

CloudLook cloud_look(const CloudLayer& layer, const CloudCrossing& crossing,
                     const Eigen::Vector3f& dir, const CloudLight& light, float footprint);

// The clouds' phase function (per steradian): a two-term blend of
// Henyey-Greenstein lobes (render/bsdf.h), a forward and a weaker backward.
float cloud_phase(float cos_theta);
// Asymmetry factor of that blend (the two-stream's g).
float cloud_asymmetry();

// Eddington two-stream slab, conservative scattering: the fraction of a
// collimated beam at cosine mu0 reflected by a slab of optical depth tau and
// asymmetry g (the rest is transmitted, directly or diffusely).
float slab_reflectance(float tau, float mu0, float g);

}  // namespace drift::render
