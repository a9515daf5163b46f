// Fuzz target: the whole scene loader (lucent::load_scene) on a bundle (fuzz_common.hpp) whose
// main file is the scene JSON, written as scene.json beside the bundle's other files, which the
// scene may name as meshes (and their MTL libraries and textures) and textures.
#include <cstddef>
#include <cstdint>

#include "fuzz_common.hpp"
#include "lucent/error.hpp"
#include "lucent/scene.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  lucent::fuzz::silence_warnings();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const lucent::fuzz::Bundle b = lucent::fuzz::parse_bundle(data, size);
  const std::string dir = lucent::fuzz::write_bundle(b, "scene.json");
  try {
    lucent::Scene s = lucent::load_scene(dir + "/scene.json");
    lucent::fuzz::check_scene(s);
  } catch (const lucent::Error&) {
    // refused with a message: fine (any other exception escapes and is reported)
  }
  return 0;
}
