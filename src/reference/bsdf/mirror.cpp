// mirror: perfect specular reflection about the shading normal with weight `reflectance`
// (Material::specular), no Fresnel term; nothing below the geometric surface.
#include "reference/bsdf/bsdf.hpp"

namespace lucent::ref {

namespace {

class Mirror final : public Bsdf {
 public:
  Mirror(const ShadingPoint& sp, const dvec3& reflectance) : Bsdf(sp), r_(reflectance) {}

  bool is_delta() const override { return true; }
  dvec3 eval(const dvec3&, const dvec3&) const override { return dvec3(0.0); }
  double pdf(const dvec3&, const dvec3&) const override { return 0; }

  BsdfSample sample(const dvec3& wo, double, double, double) const override {
    BsdfSample s;
    s.wi = reflect(wo);
    s.delta = true;
    s.valid = glm::dot(s.wi, ng_) > 0;
    s.weight = r_;
    return s;
  }

  dvec3 albedo() const override { return r_; }

  WhittedLobes whitted(const dvec3& wo) const override { return mirror_lobe(wo, r_); }

 private:
  dvec3 r_;
};

}  // namespace

std::unique_ptr<Bsdf> make_bsdf_mirror(const Scene&, const Material& m, const ShadingPoint& sp) {
  return std::make_unique<Mirror>(sp, m.specular);
}

}  // namespace lucent::ref
