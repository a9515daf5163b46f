/* lucent kernel: the constant environment: the same radiance from every direction, sampled
 * uniformly over the sphere. Parameters: lc_env_light_params. */
#ifndef LUCENT_LIGHT_ENV_CL
#define LUCENT_LIGHT_ENV_CL

static inline int light_env_sample(const lc_scene* s, __global const lc_light* L, lc_real3 p,
                                   float u1, float u2, float u3, lc_light_sample* ls) {
  ls->wi = lc_real3_from_float3(sample_uniform_sphere(u1, u2));
  ls->dist = INFINITY;
  ls->L = lc_load3(L->p.env.radiance);
  ls->pdf = L->pdf_select * (0.25f * LC_INV_PI);
  return 1;
}

static inline float light_env_pdf(const lc_scene* s, __global const lc_light* L, lc_real3 p,
                                  float3 d, lc_real dist, float cos_l) {
  return L->pdf_select * (0.25f * LC_INV_PI);
}

/* at infinity */ static inline lc_real light_env_shadow_end(const lc_scene* s,
                                                             __global const lc_light* L, lc_real3 o,
                                                             lc_real3 d, lc_real dist) {
  return dist;
}

static inline int light_env_seen_from(const lc_scene* s, __global const lc_light* L, lc_real3 o) {
  return 1;
}

static inline float3 light_env_emitted(const lc_scene* s, __global const lc_light* L, float3 d) {
  return lc_load3(L->p.env.radiance);
}

/* environments start no light paths: their caustics stay with the camera path */
static inline int light_env_emit(const lc_scene* s, __global const lc_light* L, float4 u,
                                 lc_ray* ray, float3* beta) {
  return 0;
}
#endif
