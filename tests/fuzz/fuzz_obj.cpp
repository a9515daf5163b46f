// Fuzz target: the OBJ/MTL loader (scene_detail::load_obj) on a bundle (fuzz_common.hpp) whose
// main file is the OBJ, written as m.obj beside the bundle's other files (MTL libraries,
// textures). The last byte chooses the transform: identity or a mirroring scale.
#include <cstddef>
#include <cstdint>
#include <glm/gtc/matrix_transform.hpp>

#include "fuzz_common.hpp"
#include "lucent/error.hpp"
#include "scene/loaders.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  lucent::fuzz::silence_warnings();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const lucent::fuzz::Bundle b = lucent::fuzz::parse_bundle(data, size);
  const std::string dir = lucent::fuzz::write_bundle(b, "m.obj");
  glm::dmat4 xf(1.0);
  if (size > 0 && (data[size - 1] & 1)) xf = glm::scale(glm::dmat4(1.0), glm::dvec3(-2, 1, 3e30));
  lucent::Scene scene;
  try {
    lucent::scene_detail::load_obj(scene, dir + "/m.obj", xf, -1);
    lucent::fuzz::check_scene(scene);
  } catch (const lucent::Error&) {
  }
  return 0;
}
