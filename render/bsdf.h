// The ground's reflectance at one point: rough diffuse (Oren-Nayar), and where
// it is wet a water film over it (Lekner & Dorf 1988; Jensen et al. 1999,
// "Rendering of wet materials"):
//
//   f = (1 - w) f_dry + w f_wet,   w = wetness (the share of the ground under water)
//   f_dry = A / pi * ON
//   f_wet = f_coat + A_wet / pi * ON * (1 - E(cos_i)) (1 - E(cos_o)) / (1 - E_avg)
//   f_coat = F D G / (4 cos_i cos_o)      (GGX microfacets, Walter et al. 2007, eq. 20)
//
// F is Schlick's Fresnel for water (n = 1.33); E(mu) the coat's directional
// albedo at cosine mu and E_avg its cosine-weighted mean (tabulated once):
// what the coat does not reflect reaches the ground and comes back through
// it, coupled as in Kelemen & Szirmay-Kalos 2001 ("A microfacet based coupled
// specular-matte BRDF model"), which is reciprocal and, for a white ground,
// reflects exactly 1 at every view angle (tests/render/bsdf_test.cpp).
// A_wet = A (1 - r_i) / (1 - A r_i) is the ground's albedo under water: light
// reflected by the ground comes back from the underside of the film with
// probability r_i = 1 - (1 - r_e) / n^2 ~ 0.47 (total internal reflection;
// r_e = F0 + (1 - F0) / 21 the film's reflectance from above), and every extra
// trip is absorbed with probability 1 - A (Lekner & Dorf 1988, "Why some
// things are darker when wet", Appl. Opt. 27(7)). A white ground stays white,
// a dark one darkens most: wet sand keeps about 60 % of its dry albedo.
//
// Snow (Material::forward_scattering = s) replaces part of the dry diffuse:
//
//   f_dry = (1 - s) A / pi * ON + s f_snow
//   f_snow = A [ P(-wi.wo) / (cos_i + cos_o)
//                + (1 - R(cos_i)) (1 - R(cos_o)) / (pi (1 - R_avg)) ]
//
// The first term is single scattering in a semi-infinite medium
// (Chandrasekhar 1960, "Radiative Transfer", sec. 46; Hanrahan & Krueger 1993,
// eq. 21, without the interface) with the Henyey-Greenstein phase function P
// (normalised over the sphere) of ice grains, asymmetry g = 0.89 in the
// visible (Wiscombe & Warren 1980, J. Atmos. Sci. 37): snow throws light
// forward, so a low sun seen from the far side glints off it. R(mu) is that
// lobe's directional albedo and R_avg its cosine-weighted mean (tabulated
// once); the second term gives back, diffusely, the multiply scattered rest,
// coupled as for the wet coat (Kelemen & Szirmay-Kalos 2001), so f_snow is
// reciprocal and reflects exactly A at every view angle. Snow's translucency
// over the ground beneath (thin snow reads grey) is in the albedo
// (layer_albedo, render/material.h).
#pragma once

#include <Eigen/Core>

#include "render/material.h"

namespace drift::render {

constexpr float kWaterIor = 1.33f;
// GGX alpha of the water film's surface: a film follows the ground's grain,
// so its highlight is glossy rather than a mirror image.
constexpr float kWetCoatAlpha = 0.12f;

// Schlick 1994: Fresnel reflectance at cosine `c` for normal reflectance f0.
float schlick_fresnel(float c, float f0);
// Normal-incidence reflectance of a dielectric of index `ior` in air.
constexpr float fresnel_f0(float ior) {
  return (ior - 1.0f) * (ior - 1.0f) / ((ior + 1.0f) * (ior + 1.0f));
}
// GGX normal distribution D(h) for cos(n, h) (Walter et al. 2007, eq. 33).
float ggx_d(float cos_h, float alpha);
// Smith's masking for GGX, G1 at cos(n, v) (Walter et al. 2007, eq. 34).
float ggx_g1(float cos_v, float alpha);
// The coat's directional albedo E(cos_o) (with F for water, GGX alpha
// kWetCoatAlpha) and its cosine-weighted hemispherical mean E_avg.
float coat_albedo(float cos_o);
float coat_albedo_average();
// The ground's albedo under a water film (Lekner & Dorf 1988; see above).
Eigen::Vector3f wet_albedo(const Eigen::Vector3f& albedo);

// Asymmetry of the phase function of snow grains in the visible.
constexpr float kSnowAsymmetry = 0.89f;
// Henyey & Greenstein 1941: the phase function at scattering cosine `c`,
// normalised to 1 over the sphere.
float henyey_greenstein(float c, float g);
// f_snow / A of the header comment, for unit wi, wo on the side of unit n.
float snow_reflectance(const Eigen::Vector3f& n, const Eigen::Vector3f& wi,
                       const Eigen::Vector3f& wo);
// The single-scattering lobe's directional albedo R(mu) and its mean R_avg.
float snow_single_albedo(float cos_o);
float snow_single_albedo_average();

class GroundBsdf {
 public:
  // n: unit shading normal; wo: unit direction towards the viewer.
  GroundBsdf(const Eigen::Vector3f& n, const Eigen::Vector3f& wo, const Material& material);

  // f(wi, wo) in 1/sr, without the cosine; wi points away from the surface.
  Eigen::Vector3f eval(const Eigen::Vector3f& wi) const;
  // Solid-angle density with which sample() picks wi.
  float pdf(const Eigen::Vector3f& wi) const;

  struct Sample {
    Eigen::Vector3f wi{0, 0, 1};
    Eigen::Vector3f weight{0, 0, 0};  // f cos / pdf
    float pdf = 0.0f;
  };
  // Picks the coat with probability specular_probability() (by u_lobe), else
  // a diffuse direction (u1, u2): cosine-weighted, or for snow from its
  // forward lobe with probability forward_probability(). False: no direction
  // (below the surface).
  bool sample(float u_lobe, float u1, float u2, Sample& s) const;
  // 0 for a dry material (snow included), whose sample() does not look at u_lobe.
  float specular_probability() const { return p_spec_; }
  // Snow: the share of the diffuse strategy's samples drawn from the
  // forward-scattering lobe (Henyey-Greenstein about -wo) rather than by
  // cosine; 0 for other materials.
  float forward_probability() const { return p_fwd_; }

 private:
  Eigen::Vector3f n_, wo_;
  Material m_;
  Eigen::Vector3f albedo_wet_;
  float cos_o_ = 0.0f;
  float t_o_ = 1.0f;  // 1 - E(cos_o): what the coat passes towards wo
  float p_spec_ = 0.0f;
  float p_fwd_ = 0.0f;
  // The part of eval() without the wet coat: rough diffuse and snow.
  Eigen::Vector3f dry(const Eigen::Vector3f& wi, float on) const;
  // The diffuse strategy: cosine-weighted, mixed for snow with its forward
  // lobe (u1 picks which and is reused); and its solid-angle density.
  Eigen::Vector3f diffuse_sample(float u1, float u2) const;
  float diffuse_pdf(const Eigen::Vector3f& wi, float cos_i) const;
};

}  // namespace drift::render
