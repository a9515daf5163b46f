#pragma once
// Parts shared by the reference's BSDFs, straight from docs/rendering-model.md: the exact
// dielectric Fresnel term (lucent::reference::fresnel_dielectric), refraction, the GGX /
// Trowbridge-Reitz microfacet distribution with height-correlated Smith masking-shadowing, and
// the dielectrics' Whitted lobes.
#include "reference/bsdf/bsdf.hpp"
#include "reference/common.hpp"

namespace lucent::ref {

/// The direction refracted from wo through a surface of normal m (unit, on wo's side;
/// cos_o = wo . m > 0), eta = n_transmitted / n_incident; undefined under total internal
/// reflection.
inline dvec3 refract(const dvec3& wo, const dvec3& m, double cos_o, double eta) {
  // Snell as fresnel_dielectric writes it: at eta = 1, cos_t = cos_o and wi = -wo exactly
  double cos_t = std::sqrt(std::max(0.0, eta * eta - 1 + cos_o * cos_o)) / eta;
  return glm::normalize(-wo / eta + (cos_o / eta - cos_t) * m);
}

/// GGX alpha of a material: max(roughness, 1e-3).
inline double ggx_alpha(double roughness) { return std::max(roughness, 1e-3); }

/// GGX normal distribution D(h) at cos(theta_h), in the form the model states it.
double ggx_d(double cos_h, double alpha);
/// Smith's Lambda for a direction at cosine cos_w to the normal (either side).
double ggx_lambda(double cos_w, double alpha);
/// Height-correlated Smith masking-shadowing 1 / (1 + Lambda(wo) + Lambda(wi)).
double ggx_g2(double cos_o, double cos_i, double alpha);
/// A microfacet normal drawn from D(h) cos(theta_h) about n: tan^2(theta_h) = alpha^2 u1 / (1 -
/// u1).
dvec3 ggx_sample_h(const dvec3& n, double alpha, double u1, double u2);

/// The microfacet reflection term D G2 / (4 cos_o cos_i), without Fresnel; h = normalize(wo + wi).
double ggx_specular(const dvec3& n, const dvec3& wo, const dvec3& wi, double alpha, dvec3& h);
/// Density of ggx_sample_reflect's direction wi: D(h) cos(theta_h) / (4 wo . h).
double ggx_pdf(const dvec3& n, const dvec3& wo, const dvec3& wi, double alpha);
/// wo reflected about a microfacet normal drawn by ggx_sample_h.
dvec3 ggx_sample_reflect(const dvec3& n, const dvec3& wo, double alpha, double u1, double u2);

/// The Whitted lobes of a dielectric interface about the shading normal n (smooth and rough
/// dielectrics alike): reflection with weight F, refraction with weight (1 - F) tint, without
/// the (eta_i / eta_t)^2 factor (docs/rendering-model.md, "whitted"); none when wo is below n,
/// and neither a reflection below the geometric surface (normal ng, on wo's side) nor a
/// refraction above it. eta = n_transmitted / n_incident.
WhittedLobes dielectric_whitted(const dvec3& wo, const dvec3& n, const dvec3& ng, double eta,
                                const dvec3& tint);

}  // namespace lucent::ref
