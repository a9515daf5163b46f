// Textures and environment maps: the file read with a bound, its header checked against the
// texture pixel limit and the file's length before any pixel is allocated
// (image/image_probe.cpp), then decoded to linear RGBA float: 8-bit and 16-bit data from sRGB
// (alpha stays linear), Radiance HDR, PFM and EXR kept linear with alpha 1. Row 0 at the top.
#include <cmath>
#include <filesystem>
#include <sstream>

#include "core/file_io.hpp"
#include "core/host_memory.hpp"
#include "image/image_probe.hpp"
#include "lucent/error.hpp"
#include "scene/loaders.hpp"

namespace lucent::scene_detail {

namespace fs = std::filesystem;

namespace {

// The key under which a texture is shared: the canonical path where it can be computed.
std::string texture_key(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::path(path), ec);
  return ec ? fs::path(path).lexically_normal().string() : p.string();
}

/// The bytes a pixel takes while it is decoded, the texture's own 16 (RGBA float) included: the
/// decoder's output and working buffers beside it (stb_image's 8-bit RGBA image and its zlib
/// stream's, tinyexr's planes). Counting the 16 alone let a texture pass that then took twice
/// that (an 8192x8192 PNG: 1.0 GiB counted, 2.1 GB resident) and ended in "out of memory".
std::uint64_t decode_bytes_per_pixel(const image_detail::Probe& p) {
  using image_detail::Format;
  switch (p.format) {
    case Format::Exr:
      return image_detail::exr_decode_bytes_per_pixel(p) + 16;
    case Format::Pfm:
      return 16;
    case Format::Hdr:
      return 16 + 16 + 4;
    default:
      return p.sixteen_bit ? 16 + 3 * 8 : 16 + 4 * 4;
  }
}

}  // namespace

Texture decode_texture(const unsigned char* data, std::size_t size, const std::string& path) {
  using namespace image_detail;
  Decoded d = decode_image(data, size, path, 4, kMaxTexturePixels);
  Texture t;
  t.path = path;
  t.width = d.width;
  t.height = d.height;
  t.rgba = std::move(d.pixels);
  if (d.format == Format::Pfm || d.format == Format::Exr) {
    // float formats can hold what no texture means: a NaN or an infinity makes every sample
    // that reads it non-finite, a negative value negative light (SceneBuilder::add_texture
    // refuses both too)
    for (size_t i = 0; i < t.rgba.size(); ++i) {
      if (i % 4 == 3) {
        t.rgba[i] = 1.0f;
      } else if (!(std::isfinite(t.rgba[i]) && t.rgba[i] >= 0)) {
        const size_t px = i / 4;
        std::ostringstream v;
        v << t.rgba[i];
        throw Error(path + ": pixel (" + std::to_string(px % size_t(t.width)) + ", " +
                    std::to_string(px / size_t(t.width)) + ") channel " + "RGB"[i % 4] + " is " +
                    v.str() + "; a texture's values must be finite and >= 0");
      }
    }
  }
  return t;
}

std::string texture_file_key(const std::string& path) {
  return std::string(1, '\0') + texture_key(path);
}

int load_texture(Scene& scene, const std::string& path, ObjMaterials* known) {
  // by the files loaded before (SceneBuilder's): canonicalising every loaded texture's path again
  // for each new one took 32 s (15 s of system time) for an OBJ of 1500 materials each with its
  // own texture, and a texture added from memory (SceneBuilder::add_texture) whose name was the
  // file's path stood in for the file
  const std::string key = known ? texture_file_key(path) : texture_key(path);
  if (known) {
    auto it = known->find(key);
    if (it != known->end() && it->second >= 0 &&
        static_cast<size_t>(it->second) < scene.textures.size())
      return it->second;
  } else {
    for (size_t i = 0; i < scene.textures.size(); ++i)
      if (texture_key(scene.textures[i].path) == key) return static_cast<int>(i);
  }
  const std::string bytes = io::read_file(path, image_detail::image_read_spec("texture"));
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  // the scene's textures together, as linear RGBA float, within the host limit: each is bounded,
  // not their number (a few kilobytes of compressed PNG can claim a gigabyte)
  const image_detail::Probe p =
      image_detail::probe_image(data, bytes.size(), path, image_detail::kMaxTexturePixels);
  const std::uint64_t texel = 4 * sizeof(float);
  std::uint64_t loaded = 0;
  for (const Texture& t : scene.textures) loaded += std::uint64_t(t.width) * t.height * texel;
  const std::uint64_t adds = std::uint64_t(p.width) * std::uint64_t(p.height) * texel;
  std::string what;
  const std::uint64_t limit = sys::host_memory_allowed(&what);
  if (limit > 0 && loaded + adds > limit)
    throw Error(path + ": with this " + std::to_string(p.width) + "x" + std::to_string(p.height) +
                " texture (" + sys::format_bytes(adds) + ") the scene's " +
                std::to_string(scene.textures.size() + 1) + " textures need " +
                sys::format_bytes(loaded + adds) + ", more than the limit of " +
                sys::format_bytes(limit) + " (80% of " + what +
                "): reduce the textures' resolution or number");
  const std::uint64_t pixels =
      p.decode_pixels > 0 ? p.decode_pixels : std::uint64_t(p.width) * std::uint64_t(p.height);
  const std::uint64_t decoding =
      sys::bytes_add(bytes.size(), sys::bytes_mul(pixels, decode_bytes_per_pixel(p)));
  if (limit > 0 && sys::bytes_add(loaded, decoding) > limit)
    throw Error(path + ": decoding this " + std::to_string(p.width) + "x" +
                std::to_string(p.height) + " texture needs about " + sys::format_bytes(decoding) +
                (scene.textures.empty()
                     ? std::string()
                     : " beside the scene's " + std::to_string(scene.textures.size()) +
                           " texture(s) (" + sys::format_bytes(loaded) + ")") +
                ", more than the limit of " + sys::format_bytes(limit) + " (80% of " + what +
                "): reduce the textures' resolution or number");
  scene.textures.push_back(decode_texture(data, bytes.size(), path));
  const int index = static_cast<int>(scene.textures.size() - 1);
  if (known) (*known)[key] = index;
  return index;
}

}  // namespace lucent::scene_detail
