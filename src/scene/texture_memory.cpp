// Textures from memory (lucent/scene_builder.hpp) and the sRGB decoding that image files share.
#include <algorithm>

#include "image/image_probe.hpp"
#include "lucent/error.hpp"
#include "lucent/scene_builder.hpp"
#include "scene/loaders.hpp"

namespace lucent {

namespace scene_detail {

void decode_srgb8(const std::uint8_t* data, std::size_t texels, int channels, float* rgba) {
  for (std::size_t i = 0; i < texels; ++i, data += channels, rgba += 4) {
    bool grey = channels < 3;
    for (int c = 0; c < 3; ++c) rgba[c] = image_detail::srgb8_to_linear(data[grey ? 0 : c]);
    rgba[3] = channels == 2 || channels == 4 ? data[channels - 1] / 255.0f : 1.0f;  // linear
  }
}

}  // namespace scene_detail

Texture texture_from_rgba(int width, int height, std::vector<float> rgba, std::string name) {
  Texture t;
  t.path = std::move(name);
  t.width = width;
  t.height = height;
  t.rgba = std::move(rgba);
  return t;
}

Texture texture_from_srgb8(int width, int height, int channels,
                           const std::vector<std::uint8_t>& data, std::string name) {
  if (channels < 1 || channels > 4)
    throw Error("texture_from_srgb8: channels must be 1 to 4, got " + std::to_string(channels));
  // (a size of -2 x -2 said "need 0 bytes, got 12")
  if (width < 1 || height < 1)
    throw Error("texture_from_srgb8: the size must be positive, got " + std::to_string(width) +
                "x" + std::to_string(height));
  if (width < 1 || height < 1 ||
      data.size() != std::size_t(width) * std::size_t(height) * std::size_t(channels))
    throw Error("texture_from_srgb8: " + std::to_string(width) + "x" + std::to_string(height) +
                " texels of " + std::to_string(channels) + " bytes need " +
                std::to_string(std::size_t(std::max(width, 0)) * std::size_t(std::max(height, 0)) *
                               std::size_t(channels)) +
                " bytes, got " + std::to_string(data.size()));
  Texture t;
  t.path = std::move(name);
  t.width = width;
  t.height = height;
  std::size_t texels = std::size_t(width) * std::size_t(height);
  t.rgba.resize(texels * 4);
  scene_detail::decode_srgb8(data.data(), texels, channels, t.rgba.data());
  return t;
}

}  // namespace lucent
