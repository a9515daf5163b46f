// Textures: 8-bit (and 16-bit PNG) images through stb_image, decoded from sRGB to linear; Radiance
// HDR through stb_image's float loader, PFM and EXR through lucent::read_image, all kept linear.
// Stored as linear RGBA float, row 0 at the top of the image.
#include <stb/stb_image.h>

#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "lucent/error.hpp"
#include "lucent/image.hpp"
#include "scene/loaders.hpp"

namespace lucent::scene_detail {

namespace fs = std::filesystem;

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// The key under which a texture is shared: the canonical path where it can be computed.
std::string texture_key(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::path(path), ec);
  return ec ? fs::path(path).lexically_normal().string() : p.string();
}

std::string stb_reason() {
  const char* r = stbi_failure_reason();
  return r ? r : "unknown error";
}

struct StbFree {
  void operator()(void* p) const { stbi_image_free(p); }
};

Texture decode(const std::string& path) {
  Texture t;
  t.path = path;
  std::string ext = lower_extension(path);
  if (ext == ".pfm" || ext == ".exr") {
    Image img = read_image(path);  // throws lucent::Error naming the file
    t.width = img.width;
    t.height = img.height;
    t.rgba.resize(static_cast<size_t>(img.width) * img.height * 4);
    for (size_t i = 0, n = static_cast<size_t>(img.width) * img.height; i < n; ++i) {
      for (int c = 0; c < 3; ++c) t.rgba[i * 4 + c] = img.rgb[i * 3 + c];
      t.rgba[i * 4 + 3] = 1.0f;
    }
    return t;
  }

  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw Error(path + ": cannot open texture: " + std::strerror(errno));
  stbi_set_flip_vertically_on_load(0);  // a global setting: rows must come top first
  int w = 0, h = 0, n = 0;
  size_t count = 0;
  if (stbi_is_hdr_from_file(f)) {
    std::unique_ptr<float, StbFree> data(stbi_loadf_from_file(f, &w, &h, &n, 4));
    std::fclose(f);
    if (!data) throw Error(path + ": cannot decode texture: " + stb_reason());
    count = static_cast<size_t>(w) * h * 4;
    t.rgba.assign(data.get(), data.get() + count);
  } else if (stbi_is_16_bit_from_file(f)) {
    std::unique_ptr<stbi_us, StbFree> data(stbi_load_from_file_16(f, &w, &h, &n, 4));
    std::fclose(f);
    if (!data) throw Error(path + ": cannot decode texture: " + stb_reason());
    count = static_cast<size_t>(w) * h * 4;
    t.rgba.resize(count);
    for (size_t i = 0; i < count; ++i) {
      double v = data.get()[i] / 65535.0;
      t.rgba[i] = static_cast<float>(i % 4 == 3 ? v : srgb_to_linear(v));  // alpha is linear
    }
  } else {
    std::unique_ptr<stbi_uc, StbFree> data(stbi_load_from_file(f, &w, &h, &n, 4));
    std::fclose(f);
    if (!data) throw Error(path + ": cannot decode texture: " + stb_reason());
    count = static_cast<size_t>(w) * h * 4;
    t.rgba.resize(count);
    decode_srgb8(data.get(), count / 4, 4, t.rgba.data());
  }
  if (w <= 0 || h <= 0) throw Error(path + ": texture has no pixels");
  t.width = w;
  t.height = h;
  return t;
}

}  // namespace

int load_texture(Scene& scene, const std::string& path) {
  std::string key = texture_key(path);
  for (size_t i = 0; i < scene.textures.size(); ++i)
    if (texture_key(scene.textures[i].path) == key) return static_cast<int>(i);
  scene.textures.push_back(decode(path));
  return static_cast<int>(scene.textures.size() - 1);
}

}  // namespace lucent::scene_detail
