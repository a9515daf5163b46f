// Diffuse (Lambertian) material: {"type": "diffuse", "albedo": [r, g, b] or {"texture": file}}.
// Kernel: kernels/bsdf/diffuse.cl; reference: src/reference/bsdf/diffuse.cpp.
#include "scene/material_type.hpp"

namespace lucent::scene_detail {

const MaterialTypeDef& material_type_diffuse() {
  static const MaterialTypeDef def{
      {MaterialParam::colour_param("albedo", &Material::albedo, glm::dvec3(0.8),
                                   MaterialParam::ColourOrTexture)},
      [](const Material& m, lc_material_params& p) {
        put3(p.diffuse.albedo, m.albedo);
        p.diffuse.albedo_tex = m.albedo_texture;
      }};
  return def;
}

}  // namespace lucent::scene_detail
