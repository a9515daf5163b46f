#pragma once
// The host side of a material type: its parameters in scene files and how they become the
// device's lc_<file>_params. Each entry of LC_MATERIAL_TYPES (kernels/shared/registry.h) has its
// file src/scene/materials/<file>.cpp defining
//   const MaterialTypeDef& material_type_<file>();
// and material_type_def() dispatches on the registry. The parameter table is declarative, so the
// JSON loader and the validation of scenes built in code read the same rules.
#include <glm/glm.hpp>
#include <vector>

#include "lucent/scene.hpp"
#include "shared/types.h"

namespace lucent::scene_detail {

class Reporter;  // scene/validate.hpp

/// One parameter of a material type: its scene-file key, the lucent::Material field it sets, the
/// values it accepts and its default.
struct MaterialParam {
  enum Kind {
    Colour,           ///< RGB, every component >= 0
    ColourOrTexture,  ///< Colour, or {"texture": file} (Material::albedo_texture)
    UnitInterval,     ///< a number in [0, 1]
    Ior,              ///< an index of refraction, in [kMinIor, kMaxIor]
  };
  /// Seen from its denser side, an interface of index ratio eta lets light out only within a
  /// cone of half-angle about 1/eta around its normal, and a float cosine near 1 resolves angles
  /// down to about 3.5e-4 rad only: from inside, the kernel's rough glass rendered 1.5% dark at
  /// ior 100 (image-mean z -5 against the reference) and 17% at 1000, and a smooth sphere of ior
  /// 1e4 rendered black where the reference gave 2.7e5 (the BSDF review). At 30 they agree (z
  /// -1.0, 2048 spp; KernelVsReference.RoughGlassSeenFromInsideAtTheLargestIor checks 20). Real
  /// dielectrics lie between 1 and 5, ratios of two media between their inverses. (Once the limit
  /// was 1e6, for float squares that overflowed above 1.8e19.)
  static constexpr double kMinIor = 0.05, kMaxIor = 20;
  const char* key;
  Kind kind;
  glm::dvec3 Material::*colour = nullptr;  ///< Colour and ColourOrTexture
  double Material::*number = nullptr;      ///< UnitInterval and Ior
  glm::dvec3 default_colour{0.0};
  double default_number = 0;
  /// A colour that scales the light a lobe reflects or transmits (an albedo, a reflectance, a
  /// conductor's F0, a tint): above 1 the surface gains energy, which a render warns of. False
  /// for a colour that scales a Fresnel term (plastic's specular: its reflectance averages about
  /// 0.09 at ior 1.5, and MTL files give it Ks).
  bool energy = true;

  static MaterialParam colour_param(const char* key, glm::dvec3 Material::*field, glm::dvec3 def,
                                    Kind kind = Colour) {
    MaterialParam p{key, kind};
    p.colour = field;
    p.default_colour = def;
    return p;
  }
  /// This colour with `energy` false.
  MaterialParam not_energy() const {
    MaterialParam p = *this;
    p.energy = false;
    return p;
  }
  static MaterialParam number_param(const char* key, Kind kind, double Material::*field,
                                    double def) {
    MaterialParam p{key, kind};
    p.number = field;
    p.default_number = def;
    return p;
  }
};

struct MaterialTypeDef {
  /// The scene-file parameters besides "type" and "emission" (which every type has).
  std::vector<MaterialParam> params;
  /// The device parameters (the union member of the type, shared/registry.h).
  void (*pack)(const Material& m, lc_material_params& p);
  /// Whether a material of this type can scatter by a delta lobe (nullptr: never). A caustic
  /// path needs such a surface: without one, integrator.caustics is dropped (pack_scene).
  bool (*delta)(const Material& m) = nullptr;
  /// Whether its BSDF chooses between two delta lobes, which integrator.dielectric_splits
  /// follows both of (LC_HAS_SPLITTING: render_detail::kernel_features).
  bool splits = false;
  /// The type's own checks beyond each parameter's kind (nullptr: none), after those: values
  /// that depend on each other (diffuse_mirror: albedo + reflectance <= 1) or on the textures
  /// the material uses (`textures`: the scene's, the material's albedo texture index checked).
  /// Fails at `at`, the material's place, or below it.
  void (*check)(const Material& m, const std::vector<Texture>& textures,
                const Reporter& at) = nullptr;
};

#define LUCENT_DECLARE_MATERIAL_TYPE(ID, Name, value, name, feature, file, params) \
  const MaterialTypeDef& material_type_##file();
LC_MATERIAL_TYPES(LUCENT_DECLARE_MATERIAL_TYPE)
#undef LUCENT_DECLARE_MATERIAL_TYPE

/// The definition of a material type (from the registry).
const MaterialTypeDef& material_type_def(MaterialType type);

/// v as three floats (device parameters).
inline void put3(float* dst, const glm::dvec3& v) {
  dst[0] = static_cast<float>(v.x);
  dst[1] = static_cast<float>(v.y);
  dst[2] = static_cast<float>(v.z);
}

}  // namespace lucent::scene_detail
