// The parameter checks of each material type: validate_<file>() per LC_MATERIAL_TYPES entry
// (declared in scene/validate.hpp, called by validate_material()). Each names a parameter by its
// scene-file key. These move into the per-type files src/scene/materials/<file>.cpp with the
// types' JSON parameters and packing; until then they live here, one function per type.
#include "lucent/scene.hpp"
#include "scene/validate.hpp"

namespace lucent::scene_detail {

void validate_diffuse(const Material& m, const Reporter& at) {
  check_colour(at.at("albedo"), m.albedo);
}

void validate_mirror(const Material& m, const Reporter& at) {
  check_colour(at.at("reflectance"), m.specular);
}

void validate_dielectric(const Material& m, const Reporter& at) {
  check_positive(at.at("ior"), m.ior);
  check_colour(at.at("tint"), m.specular);
}

void validate_conductor(const Material& m, const Reporter& at) {
  check_colour(at.at("specular"), m.specular);
  check_between(at.at("roughness"), m.roughness, 0, 1);
}

void validate_plastic(const Material& m, const Reporter& at) {
  check_colour(at.at("albedo"), m.albedo);
  check_colour(at.at("specular"), m.specular);
  check_between(at.at("roughness"), m.roughness, 0, 1);
  check_positive(at.at("ior"), m.ior);
}

}  // namespace lucent::scene_detail
