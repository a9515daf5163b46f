// Fuzz target: texture decoding, every format lucent reads (PNG 8/16-bit, JPEG, BMP, TGA,
// Radiance HDR, PFM, OpenEXR), from the file's bytes (scene_detail::decode_texture: the header
// checks of image/image_probe.cpp, then stb_image, tinyexr or the PFM reader).
#include <cstddef>
#include <cstdint>

#include "fuzz_common.hpp"
#include "lucent/error.hpp"
#include "scene/loaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    lucent::Texture t = lucent::scene_detail::decode_texture(data, size, "fuzz");
    lucent::fuzz::check(t.width > 0 && t.height > 0, "empty texture");
    lucent::fuzz::check(t.rgba.size() == static_cast<size_t>(t.width) * t.height * 4,
                        "texture size");
  } catch (const lucent::Error&) {
  }
  return 0;
}
