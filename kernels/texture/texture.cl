/* lucent kernel: texture lookups, bilinear filtering with repeat wrapping. Texels are linear RGBA.
 */
#ifndef LUCENT_TEXTURE_TEXTURE_CL
#define LUCENT_TEXTURE_TEXTURE_CL

static inline float4 texture_texel(const lc_scene* s, __global const lc_texture* tex, int x,
                                   int y) {
  int w = (int)tex->width, h = (int)tex->height;
  x %= w;
  if (x < 0) x += w;
  y %= h;
  if (y < 0) y += h;
  return s->texels[tex->offset + (lc_uint)y * tex->width + (lc_uint)x];
}

/* uv (0,0) is the bottom-left corner of the image (OBJ convention), v grows upwards. */
static inline float4 texture_lookup(const lc_scene* s, int index, float2 uv) {
  __global const lc_texture* tex = &s->textures[index];
  float u = uv.x - floor(uv.x), v = uv.y - floor(uv.y);
  if (!isfinite(u)) u = 0.0f; /* a NaN or infinite uv must not index outside the texture */
  if (!isfinite(v)) v = 0.0f;
  float x = u * (float)tex->width - 0.5f;
  float y = (1.0f - v) * (float)tex->height - 0.5f;
  float fx = floor(x), fy = floor(y);
  float ax = x - fx, ay = y - fy;
  int ix = (int)fx, iy = (int)fy;
  float4 a = texture_texel(s, tex, ix, iy), b = texture_texel(s, tex, ix + 1, iy);
  float4 c = texture_texel(s, tex, ix, iy + 1), d = texture_texel(s, tex, ix + 1, iy + 1);
  return (1.0f - ay) * ((1.0f - ax) * a + ax * b) + ay * ((1.0f - ax) * c + ax * d);
}

#endif
