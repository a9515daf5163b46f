// Texture lookups of the reference integrator (docs/rendering-model.md: bilinear textures on
// surfaces, repeating, clamped or mirrored, at a scaled and offset uv; nearest texels for
// environment maps).
#include "reference/texture.hpp"

#include <algorithm>
#include <cmath>

namespace lucent::ref {

namespace {

/// A coordinate of the lookup (uv after its scale and offset) folded into [0, 1] for the clamp
/// and mirror modes, whose texels are then clamped to the image: clamp reads the edge outside
/// [0, 1], mirror reads [1, 2] as [0, 1] backwards. Repeat keeps its fraction, its texels wrap.
/// (The kernel wraps texel indices instead: texture/texture.cl.)
double fold(double u, TextureWrap wrap) {
  if (!std::isfinite(u)) return 0;  // as the kernel: a NaN or infinite coordinate reads 0
  switch (wrap) {
    case TextureWrap::Clamp:
      return std::clamp(u, 0.0, 1.0);
    case TextureWrap::Mirror: {
      const double m = u - 2 * std::floor(u / 2);  // [0, 2)
      return m <= 1 ? m : 2 - m;
    }
    case TextureWrap::Repeat:
      break;
  }
  return u - std::floor(u);
}

}  // namespace

dvec3 texture_rgb(const Texture& tex, dvec2 uv) {
  return texture_rgb(tex, uv, TextureWrap::Repeat, TextureWrap::Repeat, dvec2(1.0), dvec2(0.0));
}

dvec3 texture_rgb(const Texture& tex, dvec2 uv, TextureWrap wrap_u, TextureWrap wrap_v, dvec2 scale,
                  dvec2 offset) {
  if (tex.width <= 0 || tex.height <= 0) return dvec3(0.0);
  // texel (x, y): repeat wraps it, clamp and mirror (folded coordinates) keep it in the image
  auto index = [](long i, long n, TextureWrap wrap) {
    if (wrap != TextureWrap::Repeat) return std::clamp(i, 0L, n - 1);
    i %= n;
    return i < 0 ? i + n : i;
  };
  auto texel = [&](long x, long y) {
    x = index(x, tex.width, wrap_u);
    y = index(y, tex.height, wrap_v);
    const float* t = &tex.rgba[(static_cast<size_t>(y) * tex.width + x) * 4];
    return dvec3(t[0], t[1], t[2]);
  };
  // as the kernel's texture_lookup: a NaN or infinite uv reads uv 0 (a NaN converted to long
  // was undefined behaviour, and its weights made the lookup NaN)
  const double u = fold(uv.x * scale.x + offset.x, wrap_u);
  const double v = fold(uv.y * scale.y + offset.y, wrap_v);
  double x = u * tex.width - 0.5, y = (1 - v) * tex.height - 0.5;  // row 0 is the top
  double fx = std::floor(x), fy = std::floor(y);
  double ax = x - fx, ay = y - fy;
  long ix = static_cast<long>(fx), iy = static_cast<long>(fy);
  return (1 - ay) * ((1 - ax) * texel(ix, iy) + ax * texel(ix + 1, iy)) +
         ay * ((1 - ax) * texel(ix, iy + 1) + ax * texel(ix + 1, iy + 1));
}

dvec3 equirect_rgb(const Texture& t, const dvec3& d) {
  if (t.width <= 0 || t.height <= 0) return dvec3(0.0);
  double u = 0.5 + std::atan2(d.x, -d.z) / (2 * kPi);
  double v = std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi;
  int x = std::clamp(static_cast<int>(std::floor(u * t.width)), 0, t.width - 1);
  int y = std::clamp(static_cast<int>(std::floor(v * t.height)), 0, t.height - 1);
  const float* px = &t.rgba[(static_cast<size_t>(y) * t.width + x) * 4];
  return dvec3(px[0], px[1], px[2]);
}

}  // namespace lucent::ref
