// dielectric (ior, tint = Material::specular): a smooth interface, exact Fresnel reflectance F;
// reflection with weight F, refraction with weight (1 - F) tint / eta^2 (radiance transport),
// eta = ior entering the front side, 1 / ior leaving it; total internal reflection reflects all.
// A direction on the wrong side of the geometric surface for its lobe (possible with shading
// normals) carries nothing, as for every BSDF (docs/rendering-model.md).
#include "lucent/reference.hpp"
#include "reference/bsdf/bsdf.hpp"
#include "reference/bsdf/parts.hpp"

namespace lucent::ref {

namespace {

class Dielectric final : public Bsdf {
 public:
  Dielectric(const ShadingPoint& sp, const Material& m)
      : Bsdf(sp), tint_(m.specular), eta_(sp.front ? m.ior : 1 / m.ior) {}

  bool is_delta() const override { return true; }
  dvec3 eval(const dvec3&, const dvec3&) const override { return dvec3(0.0); }
  double pdf(const dvec3&, const dvec3&) const override { return 0; }

  BsdfSample sample(const dvec3& wo, double u_lobe, double, double) const override {
    BsdfSample s;
    double co = glm::dot(wo, n_);
    if (co <= 0) return s;
    double F = reference::fresnel_dielectric(co, eta_);
    s.delta = true;
    if (u_lobe < F) {  // reflect with probability F: weight F / F
      s.wi = reflect(wo);
      s.weight = dvec3(1.0);
      // a reflection must leave above the geometric surface, a refraction below it
      s.valid = glm::dot(s.wi, ng_) > 0;
    } else {  // refract with probability 1 - F: weight tint / eta^2
      s.wi = refract(wo, n_, co, eta_);
      s.weight = tint_ / (eta_ * eta_);
      s.eta = eta_;
      s.valid = glm::dot(s.wi, ng_) < 0;
    }
    return s;
  }

  dvec3 albedo() const override { return tint_; }

  WhittedLobes whitted(const dvec3& wo) const override {
    return dielectric_whitted(wo, n_, ng_, eta_, tint_);
  }

 private:
  dvec3 tint_;
  double eta_;  ///< n_transmitted / n_incident
};

}  // namespace

std::unique_ptr<Bsdf> make_bsdf_dielectric(const Scene&, const Material& m,
                                           const ShadingPoint& sp) {
  return std::make_unique<Dielectric>(sp, m);
}

}  // namespace lucent::ref
