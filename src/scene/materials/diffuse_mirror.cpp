// Diffuse plus mirror (Whitted's k_d + k_s surface): {"type": "diffuse_mirror", "albedo":
// [r, g, b] or {"texture": file} (Material::albedo), "reflectance": [r, g, b]
// (Material::specular)}: a Lambertian base of `albedo` and a perfect mirror of weight
// `reflectance` (per channel, no Fresnel term). Components in [0, 1], and albedo + reflectance
// <= 1 in each channel (a texture's texels included; 1e-6 of rounding allowed): a surface that
// reflects more light than it receives is refused. Defaults: albedo 0.8 (diffuse's),
// reflectance 0.2 (their sum is 1).
// Kernel: kernels/bsdf/diffuse_mirror.cl; reference: src/reference/bsdf/diffuse_mirror.cpp.
#include <string>

#include "scene/material_type.hpp"
#include "scene/validate.hpp"

namespace lucent::scene_detail {

namespace {

void check_diffuse_mirror(const Material& m, const std::vector<Texture>& textures,
                          const Reporter& at) {
  const char* channel[3] = {"red", "green", "blue"};
  glm::dvec3 albedo = m.albedo;  // the texture's largest texel per channel, when textured
  std::string texel;
  if (m.albedo_texture >= 0 && static_cast<std::size_t>(m.albedo_texture) < textures.size()) {
    albedo = brightest_texel(textures[m.albedo_texture]);
    texel = " (the albedo texture's brightest texel)";
  }
  for (int c = 0; c < 3; ++c) {
    // a texture replaces the colour, whose value is then unused
    if (m.albedo_texture < 0) check_between(at.at("albedo").at(c), m.albedo[c], 0, 1);
    check_between(at.at("reflectance").at(c), m.specular[c], 0, 1);
  }
  // 1e-6: the rounding of decimal or float inputs that sum to 1 (0.7 + 0.3, 0.7f + 0.3f)
  for (int c = 0; c < 3; ++c)
    if (albedo[c] + m.specular[c] > 1 + 1e-6)
      at.at("reflectance")
          .at(c)
          .fail(
              "albedo + reflectance must be <= 1 in each channel (the surface would reflect "
              "more light than it receives), got " +
              format_number(albedo[c]) + texel + " + " + format_number(m.specular[c]) + " = " +
              format_number(albedo[c] + m.specular[c]) + " in " + channel[c]);
}

}  // namespace

const MaterialTypeDef& material_type_diffuse_mirror() {
  static const MaterialTypeDef def{
      {MaterialParam::colour_param("albedo", &Material::albedo, glm::dvec3(0.8),
                                   MaterialParam::ColourOrTexture),
       MaterialParam::colour_param("reflectance", &Material::specular, glm::dvec3(0.2))},
      [](const Material& m, lc_material_params& p) {
        put3(p.diffuse_mirror.albedo, m.albedo);
        p.diffuse_mirror.albedo_tex = m.albedo_texture;
        put3(p.diffuse_mirror.reflectance, m.specular);
      },
      [](const Material& m) { return m.specular.x > 0 || m.specular.y > 0 || m.specular.z > 0; },
      false,
      check_diffuse_mirror};
  return def;
}

}  // namespace lucent::scene_detail
