#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "lucent/scene.hpp"

namespace lucent {

/// A linear RGB float image, row 0 at the top.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  ///< width * height * 3
  // (every conversion spelt out: a consumer's -Wsign-conversion warned of this header)
  float* pixel(int x, int y) {
    return &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3];
  }
  const float* pixel(int x, int y) const {
    return &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3];
  }
};

/// How 8-bit outputs encode linear values.
struct DisplaySettings {
  Transfer transfer = Transfer::Srgb;
  double gamma = 2.2;
  double exposure = 0;  ///< stops
  ToneMap tonemap = ToneMap::Clamp;
};

/// Writes `image` in the format named by the extension: .png (8-bit, display-encoded), .pfm or
/// .exr (linear float). Throws lucent::Error naming the path on failure, and for display
/// settings a scene's film may not have (a gamma not finite and > 0, an exposure not finite, a
/// transfer or tone map outside its enum).
void write_image(const std::string& path, const Image& image, const DisplaySettings& display = {});

/// Reads .pfm, .exr (linear) or an 8-bit format (decoded from sRGB to linear). A lucent part
/// file (an .exr with lucent.checksum: a checkpoint, a --samples part) gives the image of its
/// checksummed sums, as read_render does, and a damaged one throws.
Image read_image(const std::string& path);

/// Linear value to 8-bit display value. Throws lucent::Error for the display settings
/// write_image refuses (a gamma not finite and > 0, an exposure not finite, a transfer or tone
/// map outside its enum).
unsigned char encode_display(double linear, const DisplaySettings& display);

}  // namespace lucent
