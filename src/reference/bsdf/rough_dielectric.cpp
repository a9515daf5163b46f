// rough_dielectric (ior, roughness = GGX alpha, tint = Material::specular): GGX microfacet
// reflection and transmission through a rough interface (Walter, Marschner, Li, Torrance 2007,
// "Microfacet Models for Refraction through Rough Surfaces"), two-sided like the smooth
// dielectric: eta = eta_t / eta_o (the index beyond the surface over the index on wo's side) is
// ior from the front side and 1 / ior from the back. With alpha = max(roughness, 1e-3), D the GGX
// distribution, G2 = 1 / (1 + Lambda(wo) + Lambda(wi)) (height-correlated Smith, for reflection
// and transmission alike) and F the exact dielectric Fresnel term at the microfacet:
//   reflection (wi on wo's side of n), h = normalize(wo + wi):
//     f = F(wo.h) D(h) G2 / (4 |wo.n| |wi.n|)
//   transmission (wi beyond the surface), h = +-normalize(wo + eta wi) on wo's side of n:
//     f = tint |wi.h| |wo.h| (1 - F(wo.h)) D(h) G2 / (|wi.n| |wo.n| (wo.h + eta wi.h)^2)
// which is Walter's eq. 21 for radiance transport divided through by eta_o^2: the transmitted
// radiance carries the 1 / eta^2 of the smooth dielectric's refraction weight tint / eta^2, and
// f(wo, wi) / eta_o^2 = f(wi, wo) / eta_t^2. The microfacets must face both directions
// (wo.h > 0, and wi.h > 0 for reflection, < 0 for transmission).
//
// Sampling (Walter's, deliberately not the kernel's visible-normal sampling): h from
// D(h) |h.n|, then reflection about h with probability F(wo.h), else refraction through h;
// pdf = D(h) |h.n| * (F / (4 wo.h) | (1 - F) eta^2 |wi.h| / (wo.h + eta wi.h)^2). Directions
// that land on the other side of n than their lobe's are rejected (the pdf counts only those that
// do not). Whitted: the smooth dielectric's lobes about the shading normal. Albedo AOV: tint.
// An ior within 1e-5 of 1 (an invisible interface, whatever its roughness) is a delta
// pass-through with weight tint (docs/rendering-model.md: the model's own limit as ior -> 1 still
// loses light, and the kernel cannot resolve the refraction's half vector there).
#include <cmath>

#include "lucent/reference.hpp"
#include "reference/bsdf/bsdf.hpp"
#include "reference/bsdf/parts.hpp"

namespace lucent::ref {

namespace {

class RoughDielectric final : public Bsdf {
 public:
  RoughDielectric(const ShadingPoint& sp, const Material& m)
      : Bsdf(sp),
        tint_(m.specular),
        eta_(std::abs(m.ior - 1) <= 1e-5 ? 1.0
             : sp.front                  ? m.ior
                                         : 1 / m.ior),
        alpha_(ggx_alpha(m.roughness)) {}

  bool is_delta() const override { return eta_ == 1; }

  dvec3 eval(const dvec3& wo, const dvec3& wi) const override {
    if (is_delta()) return dvec3(0.0);
    Geometry g;
    if (!geometry(wo, wi, g)) return dvec3(0.0);
    const double D = ggx_d(g.hn, alpha_), G = ggx_g2(g.co, g.ci, alpha_);
    const double F = reference::fresnel_dielectric(g.oh, eta_);
    if (g.reflect) return dvec3(F * D * G / (4 * g.co));  // f |wi.n|
    const double denom = g.oh + eta_ * g.ih;
    return tint_ * (std::abs(g.ih) * g.oh * (1 - F) * D * G / (g.co * denom * denom));
  }

  double pdf(const dvec3& wo, const dvec3& wi) const override {
    if (is_delta()) return 0;
    Geometry g;
    if (!geometry(wo, wi, g)) return 0;
    const double F = reference::fresnel_dielectric(g.oh, eta_);
    const double ph = ggx_d(g.hn, alpha_) * g.hn;  // density of h
    if (g.reflect) return ph * F / (4 * g.oh);
    const double denom = g.oh + eta_ * g.ih;
    return ph * (1 - F) * eta_ * eta_ * std::abs(g.ih) / (denom * denom);
  }

  BsdfSample sample(const dvec3& wo, double u_lobe, double u1, double u2) const override {
    const double co = glm::dot(wo, n_);
    if (co <= 0) return BsdfSample{};
    if (is_delta()) {  // ior 1: straight through
      BsdfSample s;
      s.wi = -wo;
      s.weight = tint_;
      s.delta = s.valid = true;
      return s;
    }
    const dvec3 h = ggx_sample_h(n_, alpha_, u1, u2);
    const double oh = glm::dot(wo, h);
    if (oh <= 0) return BsdfSample{};  // a microfacet that wo does not see
    const double F = reference::fresnel_dielectric(oh, eta_);
    dvec3 wi;
    if (u_lobe < F) {
      wi = glm::normalize(2 * oh * h - wo);
      if (glm::dot(wi, n_) <= 0) return BsdfSample{};
    } else {
      wi = refract(wo, h, oh, eta_);
      if (glm::dot(wi, n_) >= 0) return BsdfSample{};
    }
    BsdfSample s = sampled(wo, wi);
    if (glm::dot(wi, n_) < 0) s.eta = eta_;  // refracted: f holds 1 / eta^2 (light tracing)
    return s;
  }

  dvec3 albedo() const override { return tint_; }

  WhittedLobes whitted(const dvec3& wo) const override {
    return dielectric_whitted(wo, n_, ng_, eta_, tint_);
  }

 private:
  dvec3 tint_;
  double eta_;  ///< eta_t / eta_o
  double alpha_;

  /// The configuration of (wo, wi): cosines with n, the half vector's cosines.
  struct Geometry {
    bool reflect;
    double co, ci, hn, oh, ih;
  };

  /// False where the BSDF is 0: wo below n, wi in the surface, below the geometric surface for
  /// reflection or above it for transmission, microfacets that do not face both directions.
  bool geometry(const dvec3& wo, const dvec3& wi, Geometry& g) const {
    g.co = glm::dot(wo, n_);
    g.ci = glm::dot(wi, n_);
    if (g.co <= 0 || g.ci == 0) return false;
    g.reflect = g.ci > 0;
    if (g.reflect ? glm::dot(wi, ng_) <= 0 : glm::dot(wi, ng_) >= 0) return false;
    dvec3 h = g.reflect ? wo + wi : wo + eta_ * wi;
    double len = glm::length(h);
    if (!(len > 0)) return false;
    h /= len;
    g.hn = glm::dot(h, n_);
    if (g.hn < 0) {
      h = -h;
      g.hn = -g.hn;
    }
    g.oh = glm::dot(wo, h);
    g.ih = glm::dot(wi, h);
    return g.hn > 0 && g.oh > 0 && (g.reflect ? g.ih > 0 : g.ih < 0);
  }
};

}  // namespace

std::unique_ptr<Bsdf> make_bsdf_rough_dielectric(const Scene&, const Material& m,
                                                 const ShadingPoint& sp) {
  return std::make_unique<RoughDielectric>(sp, m);
}

}  // namespace lucent::ref
