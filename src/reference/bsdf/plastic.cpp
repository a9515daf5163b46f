// plastic (albedo, specular colour s, roughness alpha, ior eta): a GGX coating over a diffuse
// base, f = s D G2 F_d(wi.h) / (4 cos_o cos_i) + albedo / pi (1 - F_d(cos_i)) (1 - F_d(cos_o)),
// F_d the exact dielectric Fresnel term; sampled half by D(h) cos(theta_h), half by the cosine.
// Whitted: the diffuse base under point lights plus a mirror with weight F_d(cos_o) s.
#include "lucent/reference.hpp"
#include "reference/bsdf/bsdf.hpp"
#include "reference/bsdf/parts.hpp"

namespace lucent::ref {

namespace {

constexpr double kSpecularChoice = 0.5;  ///< probability of sampling the coating

class Plastic final : public Bsdf {
 public:
  Plastic(const ShadingPoint& sp, const Material& m, const dvec3& albedo)
      : Bsdf(sp), albedo_(albedo), s_(m.specular), eta_(m.ior), alpha_(ggx_alpha(m.roughness)) {}

  dvec3 eval(const dvec3& wo, const dvec3& wi) const override {
    if (below(wi)) return dvec3(0.0);
    double ci = glm::dot(wi, n_), co = glm::dot(wo, n_);
    if (co <= 0) return dvec3(0.0);
    dvec3 h;
    double spec = ggx_specular(n_, wo, wi, alpha_, h);
    double fh = reference::fresnel_dielectric(glm::dot(wi, h), eta_);
    double fi = reference::fresnel_dielectric(ci, eta_),
           fo = reference::fresnel_dielectric(co, eta_);
    return (s_ * spec * fh + albedo_ / kPi * (1 - fi) * (1 - fo)) * ci;
  }

  double pdf(const dvec3& wo, const dvec3& wi) const override {
    double ci = glm::dot(wi, n_);
    return kSpecularChoice * ggx_pdf(n_, wo, wi, alpha_) +
           (1 - kSpecularChoice) * (ci > 0 ? ci / kPi : 0);
  }

  BsdfSample sample(const dvec3& wo, double u_lobe, double u1, double u2) const override {
    if (glm::dot(wo, n_) <= 0) return BsdfSample{};
    return sampled(wo, u_lobe < kSpecularChoice ? ggx_sample_reflect(n_, wo, alpha_, u1, u2)
                                                : cosine_direction(n_, u1, u2));
  }

  dvec3 albedo() const override { return albedo_; }

  WhittedLobes whitted(const dvec3& wo) const override {
    WhittedLobes w = mirror_lobe(wo, reference::fresnel_dielectric(glm::dot(wo, n_), eta_) * s_);
    w.diffuse = true;
    w.albedo = albedo_;
    return w;
  }

 private:
  dvec3 albedo_, s_;
  double eta_, alpha_;
};

}  // namespace

std::unique_ptr<Bsdf> make_bsdf_plastic(const Scene& scene, const Material& m,
                                        const ShadingPoint& sp) {
  return std::make_unique<Plastic>(sp, m, albedo_at(scene, m, sp.uv));
}

}  // namespace lucent::ref
