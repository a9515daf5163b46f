// Placeholder until the OBJ loader lands.
#include "lucent/error.hpp"
#include "scene/loaders.hpp"

namespace lucent::scene_detail {
void load_obj(Scene&, const std::string& path, const glm::dmat4&, int) {
  throw Error(path + ": OBJ meshes are not supported yet");
}
}  // namespace lucent::scene_detail
