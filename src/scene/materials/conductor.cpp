// Rough conductor (GGX): {"type": "conductor", "specular": [r, g, b] (F0), "roughness": alpha}
// (Material::specular, Material::roughness). Kernel: kernels/bsdf/conductor.cl; reference:
// src/reference/bsdf/conductor.cpp.
#include "scene/material_type.hpp"

namespace lucent::scene_detail {

const MaterialTypeDef& material_type_conductor() {
  static const MaterialTypeDef def{
      {MaterialParam::colour_param("specular", &Material::specular, glm::dvec3(0.9)),
       MaterialParam::number_param("roughness", MaterialParam::UnitInterval, &Material::roughness,
                                   0.1)},
      [](const Material& m, lc_material_params& p) {
        put3(p.conductor.f0, m.specular);
        p.conductor.roughness = static_cast<float>(m.roughness);
      }};
  return def;
}

}  // namespace lucent::scene_detail
