// Placeholder until the texture loader lands.
#include "lucent/error.hpp"
#include "scene/loaders.hpp"

namespace lucent::scene_detail {
int load_texture(Scene&, const std::string& path) {
  throw Error(path + ": textures are not supported yet");
}
}  // namespace lucent::scene_detail
