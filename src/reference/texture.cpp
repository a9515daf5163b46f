// Texture lookups of the reference integrator (docs/rendering-model.md: bilinear, repeating
// textures on surfaces; nearest texels for environment maps).
#include "reference/texture.hpp"

#include <algorithm>
#include <cmath>

namespace lucent::ref {

dvec3 texture_rgb(const Texture& tex, dvec2 uv) {
  if (tex.width <= 0 || tex.height <= 0) return dvec3(0.0);
  auto texel = [&](long x, long y) {
    x %= tex.width;
    if (x < 0) x += tex.width;
    y %= tex.height;
    if (y < 0) y += tex.height;
    const float* t = &tex.rgba[(static_cast<size_t>(y) * tex.width + x) * 4];
    return dvec3(t[0], t[1], t[2]);
  };
  double u = uv.x - std::floor(uv.x), v = uv.y - std::floor(uv.y);
  // as the kernel's texture_lookup: a NaN or infinite uv reads uv 0 (a NaN converted to long
  // was undefined behaviour, and its weights made the lookup NaN)
  if (!std::isfinite(u)) u = 0;
  if (!std::isfinite(v)) v = 0;
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
