// Smooth dielectric (glass): {"type": "dielectric", "ior": 1.5, "tint": [r, g, b]}
// (Material::ior, Material::specular). Kernel: kernels/bsdf/dielectric.cl; reference:
// src/reference/bsdf/dielectric.cpp.
#include "scene/material_type.hpp"

namespace lucent::scene_detail {

const MaterialTypeDef& material_type_dielectric() {
  static const MaterialTypeDef def{
      {MaterialParam::number_param("ior", MaterialParam::Ior, &Material::ior, 1.5),
       MaterialParam::colour_param("tint", &Material::specular, glm::dvec3(1.0))},
      [](const Material& m, lc_material_params& p) {
        put3(p.dielectric.tint, m.specular);
        p.dielectric.ior = static_cast<float>(m.ior);
      },
      [](const Material&) { return true; },
      true};  // the reflection or the refraction, chosen with probability F
  return def;
}

}  // namespace lucent::scene_detail
