/* lucent kernel: texture lookups, bilinear filtering between texel centres. Texels are linear
 * RGBA. Textures repeat; with LC_HAS_TEXTURE_MAPPING (a scene whose textured material maps its
 * texture otherwise) each header's wrap modes, uv scale and offset are read (lucent::TextureWrap,
 * docs/rendering-model.md, "Textures"). A lookup reads texture space (uv * scale + offset):
 * triangles' uvs are mapped so by the host, spheres' by texture_map_uv. */
#ifndef LUCENT_TEXTURE_TEXTURE_CL
#define LUCENT_TEXTURE_TEXTURE_CL

/* Texel index i of an axis of n texels, wrapped by mode (LC_WRAP_*; repeat without
 * LC_HAS_TEXTURE_MAPPING). */
static inline int texture_wrap_index(int i, int n, lc_uint mode) {
#ifdef LC_HAS_TEXTURE_MAPPING
  if (mode == LC_WRAP_CLAMP) return clamp(i, 0, n - 1);
  if (mode == LC_WRAP_MIRROR) { /* period 2n: 0 .. n-1, then n-1 .. 0 */
    int p = 2 * n;
    i %= p;
    if (i < 0) i += p;
    return i < n ? i : p - 1 - i;
  }
#endif
  i %= n;
  if (i < 0) i += n;
  return i;
}

static inline float4 texture_texel(const lc_scene* s, __global const lc_texture* tex, int x, int y,
                                   lc_uint wrap_u, lc_uint wrap_v) {
  x = texture_wrap_index(x, (int)tex->width, wrap_u);
  y = texture_wrap_index(y, (int)tex->height, wrap_v);
  return s->texels[tex->offset + (lc_uint)y * tex->width + (lc_uint)x];
}

/* A texture coordinate brought into the range whose texels its lookup reads, the same texels:
 * [0, 1) for repeat, [0, 2) for mirror, [0, 1] for clamp (where every coordinate outside reads
 * the edge). A NaN or infinite coordinate reads 0 (it must not index outside the texture). */
static inline float texture_reduce(float u, lc_uint mode) {
  if (!isfinite(u)) return 0.0f;
#ifdef LC_HAS_TEXTURE_MAPPING
  if (mode == LC_WRAP_CLAMP) return clamp(u, 0.0f, 1.0f);
  if (mode == LC_WRAP_MIRROR) return u - 2.0f * floor(0.5f * u);
#endif
  return u - floor(u);
}

/* A surface's uv in texture `index`'s texture space: uv * uv_scale + uv_offset (one rounding:
 * a large offset under clamp keeps the fraction of the sum), or uv without
 * LC_HAS_TEXTURE_MAPPING. For the uvs the kernel computes (spheres'); the host maps triangles'. */
static inline float2 texture_map_uv(const lc_scene* s, int index, float2 uv) {
#ifdef LC_HAS_TEXTURE_MAPPING
  __global const lc_texture* tex = &s->textures[index];
  return fma(uv, (float2)(tex->uv_scale[0], tex->uv_scale[1]),
             (float2)(tex->uv_offset[0], tex->uv_offset[1]));
#else
  return uv;
#endif
}

/* The texel colour at uv in texture space (texture_map_uv), wrapped by the header's modes. uv
 * (0,0) is the bottom-left corner of the image (OBJ convention), v grows upwards. */
static inline float4 texture_lookup(const lc_scene* s, int index, float2 uv) {
  __global const lc_texture* tex = &s->textures[index];
#ifdef LC_HAS_TEXTURE_MAPPING
  const lc_uint wrap_u = tex->wrap & 0xffu, wrap_v = (tex->wrap >> LC_WRAP_V_SHIFT) & 0xffu;
#else
  const lc_uint wrap_u = LC_WRAP_REPEAT, wrap_v = LC_WRAP_REPEAT;
#endif
  float u = texture_reduce(uv.x, wrap_u), v = texture_reduce(uv.y, wrap_v);
  float x = u * (float)tex->width - 0.5f;
  float y = (1.0f - v) * (float)tex->height - 0.5f;
  float fx = floor(x), fy = floor(y);
  float ax = x - fx, ay = y - fy;
  int ix = (int)fx, iy = (int)fy;
  float4 a = texture_texel(s, tex, ix, iy, wrap_u, wrap_v);
  float4 b = texture_texel(s, tex, ix + 1, iy, wrap_u, wrap_v);
  float4 c = texture_texel(s, tex, ix, iy + 1, wrap_u, wrap_v);
  float4 d = texture_texel(s, tex, ix + 1, iy + 1, wrap_u, wrap_v);
  return (1.0f - ay) * ((1.0f - ax) * a + ax * b) + ay * ((1.0f - ax) * c + ax * d);
}

#endif
