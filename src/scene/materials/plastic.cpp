// Plastic: a GGX dielectric coating over a diffuse base: {"type": "plastic", "albedo": [r, g, b]
// or {"texture": file}, "specular": [r, g, b], "roughness": alpha, "ior": 1.5}.
// Kernel: kernels/bsdf/plastic.cl; reference: src/reference/bsdf/plastic.cpp.
#include "scene/material_type.hpp"

namespace lucent::scene_detail {

const MaterialTypeDef& material_type_plastic() {
  static const MaterialTypeDef def{
      {MaterialParam::colour_param("albedo", &Material::albedo, glm::dvec3(0.8),
                                   MaterialParam::ColourOrTexture),
       MaterialParam::colour_param("specular", &Material::specular, glm::dvec3(1.0)).not_energy(),
       MaterialParam::number_param("roughness", MaterialParam::UnitInterval, &Material::roughness,
                                   0.1),
       MaterialParam::number_param("ior", MaterialParam::Ior, &Material::ior, 1.5)},
      [](const Material& m, lc_material_params& p) {
        put3(p.plastic.albedo, m.albedo);
        p.plastic.albedo_tex = m.albedo_texture;
        put3(p.plastic.specular, m.specular);
        p.plastic.ior = static_cast<float>(m.ior);
        p.plastic.roughness = static_cast<float>(m.roughness);
      }};
  return def;
}

}  // namespace lucent::scene_detail
