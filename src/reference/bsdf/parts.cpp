// Parts shared by the reference's BSDFs: Fresnel, GGX, the dielectrics' Whitted lobes.
#include "reference/bsdf/parts.hpp"

#include <algorithm>
#include <cmath>

#include "lucent/reference.hpp"

namespace lucent {

double reference::fresnel_dielectric(double cos_i, double eta) {
  cos_i = std::clamp(cos_i, 0.0, 1.0);
  // eta^2 cos_t^2 = eta^2 - 1 + cos_i^2 (Snell), which at eta = 1 is cos_i^2 exactly, so cos_t
  // = cos_i and F = 0 (as the kernel writes it). cos_t^2 = 1 - (1 - cos_i^2) / eta^2 lost cos_i^2
  // in 1 - cos_i^2: at ior 1, F was 3e-11 at cos 1e-6 (a plastic of roughness 0 reflected that
  // times its huge grazing GGX peak), and below cos 1e-8 it was total reflection.
  double k = eta * eta - 1 + cos_i * cos_i;
  if (k <= 0) return 1;  // total internal reflection
  double cos_t = std::sqrt(k) / eta;
  // amplitude ratios divided through by the incident index
  double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

namespace ref {

namespace {

double tan2_of(double c) {
  double c2 = c * c;
  return (1 - c2) / c2;
}

}  // namespace

double ggx_d(double cos_h, double alpha) {
  if (cos_h <= 0) return 0;
  double a2 = alpha * alpha, c4 = cos_h * cos_h * cos_h * cos_h, s = a2 + tan2_of(cos_h);
  return a2 / (kPi * c4 * s * s);
}

double ggx_lambda(double cos_w, double alpha) {
  return 0.5 * (-1 + std::sqrt(1 + alpha * alpha * tan2_of(cos_w)));
}

double ggx_g2(double cos_o, double cos_i, double alpha) {
  return 1 / (1 + ggx_lambda(cos_o, alpha) + ggx_lambda(cos_i, alpha));
}

dvec3 ggx_sample_h(const dvec3& n, double alpha, double u1, double u2) {
  double tan2 = alpha * alpha * u1 / (1 - u1);
  double ch = 1 / std::sqrt(1 + tan2), sh = std::sqrt(std::max(0.0, 1 - ch * ch));
  double phi = 2 * kPi * u2;
  dvec3 t, b;
  basis(n, t, b);
  return sh * std::cos(phi) * t + sh * std::sin(phi) * b + ch * n;
}

double ggx_specular(const dvec3& n, const dvec3& wo, const dvec3& wi, double alpha, dvec3& h) {
  double co = glm::dot(wo, n), ci = glm::dot(wi, n);
  h = glm::normalize(wo + wi);
  return ggx_d(glm::dot(h, n), alpha) * ggx_g2(co, ci, alpha) / (4 * co * ci);
}

double ggx_pdf(const dvec3& n, const dvec3& wo, const dvec3& wi, double alpha) {
  dvec3 h = glm::normalize(wo + wi);
  double ch = glm::dot(h, n), oh = glm::dot(wo, h);
  if (ch <= 0 || oh <= 0) return 0;
  return ggx_d(ch, alpha) * ch / (4 * oh);
}

dvec3 ggx_sample_reflect(const dvec3& n, const dvec3& wo, double alpha, double u1, double u2) {
  dvec3 h = ggx_sample_h(n, alpha, u1, u2);
  return glm::normalize(2 * glm::dot(wo, h) * h - wo);
}

WhittedLobes dielectric_whitted(const dvec3& wo, const dvec3& n, const dvec3& ng, double eta,
                                const dvec3& tint) {
  WhittedLobes w;
  double co = glm::dot(wo, n);
  if (co <= 0) return w;
  double F = reference::fresnel_dielectric(co, eta);
  w.reflect_dir = glm::normalize(2 * co * n - wo);
  w.reflect = glm::dot(w.reflect_dir, ng) > 0;
  w.reflect_weight = dvec3(F);
  if (F < 1) {
    w.transmit_dir = refract(wo, n, co, eta);
    w.transmit = glm::dot(w.transmit_dir, ng) < 0;
    w.transmit_weight = (1 - F) * tint;
  }
  return w;
}

}  // namespace ref

}  // namespace lucent
