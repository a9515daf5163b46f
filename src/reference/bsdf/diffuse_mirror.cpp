// diffuse_mirror (albedo, reflectance r = Material::specular): a Lambertian base plus a perfect
// mirror of weight r, no Fresnel term: f = albedo / pi + r delta(wi - mirror(wo)) / cos. The
// reference's own strategy: the mirror with probability 1/2 when both parts are there (1 or 0
// when one is missing), else a direction uniform over the hemisphere (the kernel chooses by
// channel sums and samples the cosine). eval and pdf are the diffuse part's; the mirror is a
// delta sample. Whitted: the diffuse part under point lights plus r x the mirror ray.
#include "reference/bsdf/bsdf.hpp"

namespace lucent::ref {

namespace {

class DiffuseMirror final : public Bsdf {
 public:
  DiffuseMirror(const ShadingPoint& sp, const dvec3& albedo, const dvec3& r)
      : Bsdf(sp), albedo_(albedo), r_(r) {
    bool diffuse = max3(albedo_) > 0, mirror = max3(r_) > 0;
    mirror_choice_ = mirror ? (diffuse ? 0.5 : 1.0) : 0.0;
  }

  dvec3 eval(const dvec3&, const dvec3& wi) const override {
    if (below(wi)) return dvec3(0.0);
    return albedo_ / kPi * glm::dot(wi, n_);
  }

  double pdf(const dvec3&, const dvec3& wi) const override {
    return glm::dot(wi, n_) > 0 ? (1 - mirror_choice_) / (2 * kPi) : 0;
  }

  BsdfSample sample(const dvec3& wo, double u_lobe, double u1, double u2) const override {
    if (glm::dot(wo, n_) <= 0) return BsdfSample{};
    if (u_lobe < mirror_choice_) {
      BsdfSample s;
      s.wi = reflect(wo);
      s.delta = true;
      s.valid = glm::dot(s.wi, ng_) > 0;
      s.weight = r_ / mirror_choice_;
      return s;
    }
    // uniform over the hemisphere of n
    dvec3 t, b;
    basis(n_, t, b);
    double z = u1, rr = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u2;
    return sampled(wo, glm::normalize(rr * std::cos(phi) * t + rr * std::sin(phi) * b + z * n_));
  }

  dvec3 albedo() const override { return albedo_ + r_; }

  WhittedLobes whitted(const dvec3& wo) const override {
    WhittedLobes w = mirror_lobe(wo, r_);
    w.reflect = w.reflect && max3(r_) > 0;
    w.diffuse = true;
    w.albedo = albedo_;
    return w;
  }

 private:
  dvec3 albedo_, r_;
  double mirror_choice_;
};

}  // namespace

std::unique_ptr<Bsdf> make_bsdf_diffuse_mirror(const Scene& scene, const Material& m,
                                               const ShadingPoint& sp) {
  return std::make_unique<DiffuseMirror>(sp, albedo_at(scene, m, sp.uv), m.specular);
}

}  // namespace lucent::ref
