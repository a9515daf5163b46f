// Rough dielectric (GGX microfacet glass): {"type": "rough_dielectric", "ior": 1.5,
// "roughness": alpha, "tint": [r, g, b]} (Material::ior, Material::roughness, Material::specular).
// Kernel: kernels/bsdf/rough_dielectric.cl; reference: src/reference/bsdf/rough_dielectric.cpp.
#include <cmath>

#include "scene/material_type.hpp"

namespace lucent::scene_detail {

namespace {

/// The index of refraction the device gets: 1 (no interface: straight through) within 1e-5 of 1.
/// There the generalized half vector of refraction, wo + eta wi, is a difference of nearly equal
/// float vectors: an ior one float step above 1 rendered 14 standard errors darker than the
/// reference (in double). Refraction through such an interface bends a ray by at most about
/// 1e-5 radians, and its Fresnel reflectance is below 1e-10: nothing an image shows.
float device_ior(const Material& m) {
  return std::abs(m.ior - 1.0) <= 1e-5 ? 1.0f : static_cast<float>(m.ior);
}

}  // namespace

const MaterialTypeDef& material_type_rough_dielectric() {
  static const MaterialTypeDef def{
      {MaterialParam::number_param("ior", MaterialParam::Ior, &Material::ior, 1.5),
       MaterialParam::number_param("roughness", MaterialParam::UnitInterval, &Material::roughness,
                                   0.1),
       MaterialParam::colour_param("tint", &Material::specular, glm::dvec3(1.0))},
      [](const Material& m, lc_material_params& p) {
        put3(p.rough_dielectric.tint, m.specular);
        p.rough_dielectric.ior = device_ior(m);
        p.rough_dielectric.roughness = static_cast<float>(m.roughness);
      },
      // at ior 1 (as the device sees it) the transmission goes straight through: a delta lobe
      [](const Material& m) { return device_ior(m) == 1.0f; }};
  return def;
}

}  // namespace lucent::scene_detail
