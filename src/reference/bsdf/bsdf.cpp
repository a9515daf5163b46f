// The reference's BSDF dispatch: Material::type -> make_bsdf_<file>, generated from
// LC_MATERIAL_TYPES; the parts every BSDF shares.
#include "reference/bsdf/bsdf.hpp"

#include <string>

#include "lucent/error.hpp"
#include "reference/texture.hpp"

namespace lucent::ref {

BsdfSample Bsdf::sampled(const dvec3& wo, const dvec3& wi) const {
  BsdfSample s;
  s.wi = wi;
  dvec3 f = eval(wo, s.wi);
  s.pdf = pdf(wo, s.wi);
  if (s.pdf <= 0 || max3(f) <= 0) return s;
  s.weight = f / s.pdf;
  s.valid = true;
  return s;
}

dvec3 Bsdf::reflect(const dvec3& wo) const {
  return glm::normalize(2 * glm::dot(wo, n_) * n_ - wo);
}

WhittedLobes Bsdf::mirror_lobe(const dvec3& wo, const dvec3& weight) const {
  WhittedLobes w;
  w.reflect_dir = reflect(wo);
  w.reflect = glm::dot(w.reflect_dir, ng_) > 0;
  w.reflect_weight = weight;
  return w;
}

dvec3 albedo_at(const Scene& scene, const Material& m, dvec2 uv) {
  int tex = m.albedo_texture;
  if (tex >= 0 && tex < static_cast<int>(scene.textures.size()))
    return texture_rgb(scene.textures[tex], uv, m.albedo_wrap_u, m.albedo_wrap_v, m.albedo_uv_scale,
                       m.albedo_uv_offset);
  return m.albedo;
}

std::unique_ptr<Bsdf> make_bsdf(const Scene& scene, const Material& m, const ShadingPoint& sp) {
  switch (m.type) {
#define LUCENT_REF_BSDF_CASE(ID, Name, value, name, feature, file, ...) \
  case MaterialType::Name:                                              \
    return make_bsdf_##file(scene, m, sp);
    LC_MATERIAL_TYPES(LUCENT_REF_BSDF_CASE)
#undef LUCENT_REF_BSDF_CASE
  }
  throw Error(scene.path + ": material '" + m.name + "': unknown type " +
              std::to_string(static_cast<int>(m.type)));
}

}  // namespace lucent::ref
