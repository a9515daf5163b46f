#pragma once
// Texture lookups of the reference integrator.
#include "reference/common.hpp"

namespace lucent::ref {

/// Bilinear, repeating lookup of a texture's RGB; uv (0, 0) is the bottom-left corner.
dvec3 texture_rgb(const Texture& tex, dvec2 uv);

/// The same lookup at uv * scale + offset, wrapped in u and v by its modes
/// (docs/rendering-model.md, "Textures").
dvec3 texture_rgb(const Texture& tex, dvec2 uv, TextureWrap wrap_u, TextureWrap wrap_v, dvec2 scale,
                  dvec2 offset);

/// Nearest (piecewise constant) lookup of an equirectangular image in direction d:
/// u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi, v = 0 the top row.
dvec3 equirect_rgb(const Texture& tex, const dvec3& d);

}  // namespace lucent::ref
