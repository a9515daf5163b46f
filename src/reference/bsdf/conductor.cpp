// conductor (specular = F0 colour, roughness = GGX alpha): GGX microfacet reflection,
// f = D G2 F / (4 cos_o cos_i) with Schlick's F(c) = F0 + (1 - F0)(1 - c)^5; sampled by
// D(h) cos(theta_h). Whitted: a mirror with weight F0.
#include <algorithm>
#include <cmath>

#include "reference/bsdf/bsdf.hpp"
#include "reference/bsdf/parts.hpp"

namespace lucent::ref {

namespace {

class Conductor final : public Bsdf {
 public:
  Conductor(const ShadingPoint& sp, const Material& m)
      : Bsdf(sp), f0_(m.specular), alpha_(ggx_alpha(m.roughness)) {}

  dvec3 eval(const dvec3& wo, const dvec3& wi) const override {
    if (below(wi)) return dvec3(0.0);
    double ci = glm::dot(wi, n_), co = glm::dot(wo, n_);
    if (co <= 0) return dvec3(0.0);
    dvec3 h;
    double spec = ggx_specular(n_, wo, wi, alpha_, h);
    double c = std::clamp(glm::dot(wi, h), 0.0, 1.0);
    dvec3 F = f0_ + (dvec3(1.0) - f0_) * std::pow(1 - c, 5.0);
    return F * spec * ci;
  }

  double pdf(const dvec3& wo, const dvec3& wi) const override {
    return ggx_pdf(n_, wo, wi, alpha_);
  }

  BsdfSample sample(const dvec3& wo, double, double u1, double u2) const override {
    if (glm::dot(wo, n_) <= 0) return BsdfSample{};
    return sampled(wo, ggx_sample_reflect(n_, wo, alpha_, u1, u2));
  }

  dvec3 albedo() const override { return f0_; }

  WhittedLobes whitted(const dvec3& wo) const override { return mirror_lobe(wo, f0_); }

 private:
  dvec3 f0_;
  double alpha_;
};

}  // namespace

std::unique_ptr<Bsdf> make_bsdf_conductor(const Scene&, const Material& m, const ShadingPoint& sp) {
  return std::make_unique<Conductor>(sp, m);
}

}  // namespace lucent::ref
