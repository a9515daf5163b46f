// Perfect mirror: {"type": "mirror", "reflectance": [r, g, b]} (Material::specular).
// Kernel: kernels/bsdf/mirror.cl; reference: src/reference/bsdf/mirror.cpp.
#include "scene/material_type.hpp"

namespace lucent::scene_detail {

const MaterialTypeDef& material_type_mirror() {
  static const MaterialTypeDef def{
      {MaterialParam::colour_param("reflectance", &Material::specular, glm::dvec3(1.0))},
      [](const Material& m, lc_material_params& p) { put3(p.mirror.reflectance, m.specular); },
      [](const Material&) { return true; }};
  return def;
}

}  // namespace lucent::scene_detail
