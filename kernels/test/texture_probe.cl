/* lucent test kernel: the device's texture lookup (texture/texture.cl) on textures packed by the
 * host (tests/test_texture_kernel.cpp): out[i] = texture_lookup(texture index[i], uv[i]), uv[i]
 * mapped to texture space by texture_map_uv first, as a sphere's is. */
/* clang-format off */
#include "shared/types.h"
#include "util/math.cl"
#include "scene/scene.cl"
#include "texture/texture.cl"
/* clang-format on */

__kernel void probe_texture_lookup(__global const lc_texture* textures,
                                   __global const float4* texels, __global const int* index,
                                   __global const float2* uv, __global float4* out) {
  size_t i = get_global_id(0);
  lc_scene s = {0}; /* only the texture fields are used */
  s.textures = textures;
  s.texels = texels;
  out[i] = texture_lookup(&s, index[i], texture_map_uv(&s, index[i], uv[i]));
}
