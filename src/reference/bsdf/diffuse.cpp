// diffuse: f = albedo / pi (the albedo from the texture when there is one).
#include "reference/bsdf/bsdf.hpp"

namespace lucent::ref {

namespace {

class Diffuse final : public Bsdf {
 public:
  Diffuse(const ShadingPoint& sp, const dvec3& albedo) : Bsdf(sp), albedo_(albedo) {}

  dvec3 eval(const dvec3&, const dvec3& wi) const override {
    if (below(wi)) return dvec3(0.0);
    return albedo_ / kPi * glm::dot(wi, n_);
  }

  double pdf(const dvec3&, const dvec3& wi) const override {
    double ci = glm::dot(wi, n_);
    return ci > 0 ? ci / kPi : 0;
  }

  BsdfSample sample(const dvec3& wo, double, double u1, double u2) const override {
    return sampled(wo, cosine_direction(n_, u1, u2));
  }

  dvec3 albedo() const override { return albedo_; }

  WhittedLobes whitted(const dvec3&) const override {
    WhittedLobes w;
    w.diffuse = true;
    w.albedo = albedo_;
    return w;
  }

 private:
  dvec3 albedo_;
};

}  // namespace

std::unique_ptr<Bsdf> make_bsdf_diffuse(const Scene& scene, const Material& m,
                                        const ShadingPoint& sp) {
  return std::make_unique<Diffuse>(sp, albedo_at(scene, m, sp.uv));
}

}  // namespace lucent::ref
