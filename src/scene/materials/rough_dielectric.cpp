// Rough dielectric (GGX microfacet glass): {"type": "rough_dielectric", "ior": 1.5,
// "roughness": alpha, "tint": [r, g, b]} (Material::ior, Material::roughness, Material::specular).
// Kernel: kernels/bsdf/rough_dielectric.cl; reference: src/reference/bsdf/rough_dielectric.cpp.
#include "scene/material_type.hpp"

namespace lucent::scene_detail {

const MaterialTypeDef& material_type_rough_dielectric() {
  static const MaterialTypeDef def{
      {MaterialParam::number_param("ior", MaterialParam::Ior, &Material::ior, 1.5),
       MaterialParam::number_param("roughness", MaterialParam::UnitInterval, &Material::roughness,
                                   0.1),
       MaterialParam::colour_param("tint", &Material::specular, glm::dvec3(1.0))},
      [](const Material& m, lc_material_params& p) {
        put3(p.rough_dielectric.tint, m.specular);
        p.rough_dielectric.ior = static_cast<float>(m.ior);
        p.rough_dielectric.roughness = static_cast<float>(m.roughness);
      },
      // at ior 1 (as the device sees it) the transmission goes straight through: a delta lobe
      [](const Material& m) { return static_cast<float>(m.ior) == 1.0f; }};
  return def;
}

}  // namespace lucent::scene_detail
