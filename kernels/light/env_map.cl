/* lucent kernel: the equirectangular environment map, nearest texel (docs/rendering-model.md),
 * importance-sampled by texel luminance times sin(theta): a CDF over the texels in light_cdf
 * (src/render/lights.cpp), then uniformly within the texel in (u, v). Parameters:
 * lc_env_map_light_params (scale, texture, the CDF's first entry). */
#ifndef LUCENT_LIGHT_ENV_MAP_CL
#define LUCENT_LIGHT_ENV_MAP_CL

/* Radiance towards -d, and the texel d falls in. */
static inline float3 env_map_radiance(const lc_scene* s, __global const lc_light* L, float3 d,
                                      lc_uint* texel) {
  __global const lc_texture* tex = &s->textures[L->p.env_map.texture];
  float u = 0.5f + atan2(d.x, -d.z) * (0.5f * LC_INV_PI);
  float v = acos(clamp(d.y, -1.0f, 1.0f)) * LC_INV_PI;
  int x = clamp((int)(u * (float)tex->width), 0, (int)tex->width - 1);
  int y = clamp((int)(v * (float)tex->height), 0, (int)tex->height - 1);
  *texel = (lc_uint)y * tex->width + (lc_uint)x;
  return lc_load3(L->p.env_map.scale) * s->texels[tex->offset + *texel].xyz;
}

static inline int light_env_map_sample(const lc_scene* s, __global const lc_light* L, lc_real3 p,
                                       float u1, float u2, float u3, lc_light_sample* ls) {
  __global const lc_texture* tex = &s->textures[L->p.env_map.texture];
  lc_uint n = tex->width * tex->height;
  __global const float* cdf = s->light_cdf + L->p.env_map.cdf; /* n + 1 entries, cdf[0] = 0 */
  /* u1 chooses the texel: the CDF lies on the 2^-24 lattice of u1 (src/render/lights.cpp), so
   * hi - lo is exactly the texel's probability. The point inside the texel comes from two other
   * numbers: u1 rescaled to the texel would take only (hi - lo) 2^24 values, a handful for the
   * texels of a large map. */
  lc_uint k = lc_cdf_search(cdf + 1, n, u1);
  float lo = cdf[k], hi = cdf[k + 1];
  lc_uint x = k % tex->width, y = k / tex->width;
  float u = ((float)x + u3) / (float)tex->width;
  float v = ((float)y + u2) / (float)tex->height;
  /* theta = pi v, phi = 2 pi (u - 1/2) */
  float st = sinpi(v);
  if (!(st > 0.0f)) return 0;
  float2 cp = lc_unit_circle(u - 0.5f);
  ls->wi = lc_real3_from_float3((float3)(st * cp.y, cospi(v), -st * cp.x));
  ls->dist = INFINITY;
  ls->L = lc_load3(L->p.env_map.scale) * s->texels[tex->offset + k].xyz;
  ls->pdf = L->pdf_select * (hi - lo) * (float)n / (2.0f * LC_PI * LC_PI * st);
  return ls->pdf > 0.0f;
}

/* the texel's probability over its solid angle */
static inline float light_env_map_pdf(const lc_scene* s, __global const lc_light* L, lc_real3 p,
                                      float3 d, lc_real dist, float cos_l) {
  lc_uint texel;
  env_map_radiance(s, L, d, &texel);
  __global const lc_texture* tex = &s->textures[L->p.env_map.texture];
  __global const float* cdf = s->light_cdf + L->p.env_map.cdf;
  float pr = cdf[texel + 1] - cdf[texel];
  float sin_t = sqrt(d.x * d.x + d.z * d.z); /* not sqrt(1 - y^2): precise near the poles */
  if (sin_t <= 0.0f) return 0.0f;
  return L->pdf_select * (pr * (float)(tex->width * tex->height) / (2.0f * LC_PI * LC_PI * sin_t));
}

/* at infinity */ static inline lc_real light_env_map_shadow_end(const lc_scene* s,
                                                                 __global const lc_light* L,
                                                                 lc_real3 o, lc_real3 d,
                                                                 lc_real dist) {
  return dist;
}

static inline int light_env_map_seen_from(const lc_scene* s, __global const lc_light* L,
                                          lc_real3 o) {
  return 1;
}

static inline float3 light_env_map_emitted(const lc_scene* s, __global const lc_light* L,
                                           float3 d) {
  lc_uint texel;
  return env_map_radiance(s, L, d, &texel);
}

/* environments start no light paths: their caustics stay with the camera path */
static inline int light_env_map_emit(const lc_scene* s, __global const lc_light* L, float4 u,
                                     lc_ray* ray, float3* beta) {
  return 0;
}
#endif
