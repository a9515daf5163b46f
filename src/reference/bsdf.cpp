// Reference integrator: its own materials, straight from docs/rendering-model.md. Every function
// works in world space with the shading normal n oriented towards wo.
#include <algorithm>
#include <cmath>

#include "lucent/reference.hpp"
#include "reference/reference_internal.hpp"

namespace lucent {

double reference::fresnel_dielectric(double cos_i, double eta) {
  cos_i = std::clamp(cos_i, 0.0, 1.0);
  double sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return 1;  // total internal reflection
  double cos_t = std::sqrt(1 - sin2_t);
  // amplitude ratios divided through by the incident index
  double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

namespace ref {

namespace {

/// Orthonormal t, b completing n.
void basis(const dvec3& n, dvec3& t, dvec3& b) {
  dvec3 a = std::abs(n.x) > 0.5 ? dvec3(0, 1, 0) : dvec3(1, 0, 0);
  t = glm::normalize(glm::cross(a, n));
  b = glm::cross(n, t);
}

dvec3 cosine_direction(const dvec3& n, double u1, double u2) {
  dvec3 t, b;
  basis(n, t, b);
  double r = std::sqrt(u1), phi = 2 * kPi * u2;
  return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0, 1 - u1)) * n);
}

double tan2_of(double c) {
  double c2 = c * c;
  return (1 - c2) / c2;
}

/// GGX normal distribution, in the form the model states it.
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

double alpha_of(const Material& m) { return std::max(m.roughness, 1e-3); }

/// The microfacet specular term D G2 / (4 cos_o cos_i), without Fresnel.
double ggx_specular(const dvec3& n, const dvec3& wo, const dvec3& wi, double alpha, dvec3& h) {
  double co = glm::dot(wo, n), ci = glm::dot(wi, n);
  h = glm::normalize(wo + wi);
  return ggx_d(glm::dot(h, n), alpha) * ggx_g2(co, ci, alpha) / (4 * co * ci);
}

/// Density of the half vector h ~ D(h) cos(theta_h), converted to the reflected direction.
double ggx_pdf(const dvec3& n, const dvec3& wo, const dvec3& wi, double alpha) {
  dvec3 h = glm::normalize(wo + wi);
  double ch = glm::dot(h, n), oh = glm::dot(wo, h);
  if (ch <= 0 || oh <= 0) return 0;
  return ggx_d(ch, alpha) * ch / (4 * oh);
}

/// Reflected direction about a half vector drawn from D(h) cos(theta_h):
/// tan^2(theta_h) = alpha^2 u1 / (1 - u1).
dvec3 ggx_sample(const dvec3& n, const dvec3& wo, double alpha, double u1, double u2) {
  double tan2 = alpha * alpha * u1 / (1 - u1);
  double ch = 1 / std::sqrt(1 + tan2), sh = std::sqrt(std::max(0.0, 1 - ch * ch));
  double phi = 2 * kPi * u2;
  dvec3 t, b;
  basis(n, t, b);
  dvec3 h = sh * std::cos(phi) * t + sh * std::sin(phi) * b + ch * n;
  return glm::normalize(2 * glm::dot(wo, h) * h - wo);
}

constexpr double kPlasticSpecularChoice = 0.5;

}  // namespace

bool Bsdf::is_delta() const {
  return m->type == MaterialType::Mirror || m->type == MaterialType::Dielectric;
}

dvec3 Bsdf::eval(const dvec3& wo, const dvec3& wi) const {
  if (is_delta()) return dvec3(0.0);
  double ci = glm::dot(wi, n), co = glm::dot(wo, n);
  if (glm::dot(wi, ng) <= 0 || ci <= 0) return dvec3(0.0);  // below the surface
  switch (m->type) {
    case MaterialType::Diffuse:
      return albedo / kPi * ci;
    case MaterialType::Conductor: {
      if (co <= 0) return dvec3(0.0);
      dvec3 h;
      double spec = ggx_specular(n, wo, wi, alpha_of(*m), h);
      double c = std::clamp(glm::dot(wi, h), 0.0, 1.0);
      dvec3 F = m->specular + (dvec3(1.0) - m->specular) * std::pow(1 - c, 5.0);
      return F * spec * ci;
    }
    case MaterialType::Plastic: {
      if (co <= 0) return dvec3(0.0);
      dvec3 h;
      double spec = ggx_specular(n, wo, wi, alpha_of(*m), h);
      double eta = m->ior;
      double fh = reference::fresnel_dielectric(glm::dot(wi, h), eta);
      double fi = reference::fresnel_dielectric(ci, eta), fo = reference::fresnel_dielectric(co, eta);
      return (m->specular * spec * fh + albedo / kPi * (1 - fi) * (1 - fo)) * ci;
    }
    default:
      return dvec3(0.0);
  }
}

double Bsdf::pdf(const dvec3& wo, const dvec3& wi) const {
  double ci = glm::dot(wi, n);
  switch (m->type) {
    case MaterialType::Diffuse:
      return ci > 0 ? ci / kPi : 0;
    case MaterialType::Conductor:
      return ggx_pdf(n, wo, wi, alpha_of(*m));
    case MaterialType::Plastic:
      return kPlasticSpecularChoice * ggx_pdf(n, wo, wi, alpha_of(*m)) +
             (1 - kPlasticSpecularChoice) * (ci > 0 ? ci / kPi : 0);
    default:
      return 0;
  }
}

BsdfSample Bsdf::sample(const dvec3& wo, double u_lobe, double u1, double u2) const {
  BsdfSample s;
  double co = glm::dot(wo, n);
  switch (m->type) {
    case MaterialType::Mirror: {
      s.wi = glm::normalize(2 * co * n - wo);
      s.delta = true;
      s.valid = glm::dot(s.wi, ng) > 0;
      s.weight = m->specular;
      return s;
    }
    case MaterialType::Dielectric: {
      if (co <= 0) return s;
      double eta = front ? m->ior : 1 / m->ior;  // n_transmitted / n_incident
      double F = reference::fresnel_dielectric(co, eta);
      s.delta = true;
      s.valid = true;
      if (u_lobe < F) {  // reflect with probability F: weight F / F
        s.wi = glm::normalize(2 * co * n - wo);
        s.weight = dvec3(1.0);
      } else {  // refract with probability 1 - F: weight tint / eta^2
        double cos_t = std::sqrt(std::max(0.0, 1 - (1 - co * co) / (eta * eta)));
        s.wi = glm::normalize(-wo / eta + (co / eta - cos_t) * n);
        s.weight = m->specular / (eta * eta);
      }
      return s;
    }
    case MaterialType::Diffuse:
      s.wi = cosine_direction(n, u1, u2);
      break;
    case MaterialType::Conductor:
      if (co <= 0) return s;
      s.wi = ggx_sample(n, wo, alpha_of(*m), u1, u2);
      break;
    case MaterialType::Plastic:
      if (co <= 0) return s;
      s.wi = u_lobe < kPlasticSpecularChoice ? ggx_sample(n, wo, alpha_of(*m), u1, u2)
                                             : cosine_direction(n, u1, u2);
      break;
  }
  dvec3 f = eval(wo, s.wi);
  s.pdf = pdf(wo, s.wi);
  if (s.pdf <= 0 || max3(f) <= 0) return s;
  s.weight = f / s.pdf;
  s.valid = true;
  return s;
}

Bsdf make_bsdf(const Scene& scene, const Surface& s) {
  Bsdf b;
  b.m = &scene.materials[s.material];
  b.albedo = b.m->albedo;
  int tex = b.m->albedo_texture;
  if (tex >= 0 && tex < static_cast<int>(scene.textures.size()))
    b.albedo = texture_rgb(scene.textures[tex], s.uv);
  b.n = s.ns;
  b.ng = s.ng;
  b.front = s.front;
  return b;
}

}  // namespace ref

}  // namespace lucent
