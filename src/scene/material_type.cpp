#include "scene/material_type.hpp"

#include "lucent/error.hpp"

namespace lucent::scene_detail {

const MaterialTypeDef& material_type_def(MaterialType type) {
#define LUCENT_MATERIAL_DEF(ID, Name, value, name, feature, file, params) \
  if (type == MaterialType::Name) return material_type_##file();
  LC_MATERIAL_TYPES(LUCENT_MATERIAL_DEF)
#undef LUCENT_MATERIAL_DEF
  throw Error("material type " + std::to_string(static_cast<int>(type)) + " is not registered");
}

}  // namespace lucent::scene_detail
