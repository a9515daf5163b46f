/* lucent kernel: point lights: intensity I (W/sr) at a position, radiance I / r^2 arriving from
 * it; a delta light (no MIS, never hit by a ray). Parameters: lc_point_light_params. */
#ifndef LUCENT_LIGHT_POINT_CL
#define LUCENT_LIGHT_POINT_CL

static inline int light_point_sample(const lc_scene* s, __global const lc_light* L, lc_real3 p,
                                     float u1, float u2, float u3, lc_light_sample* ls) {
  lc_real3 to = lc_load3r(L->p.point.position) - p;
  lc_real d2 = dot(to, to);
  if (!(d2 > LC_REAL(0.0))) return 0;
  ls->dist = sqrt(d2);
  ls->wi = to / ls->dist;
  ls->L = lc_load3(L->p.point.intensity) / (float)d2;
  ls->pdf = L->pdf_select;
  ls->delta = 1;
  /* no surface to stop short of: the relative margin let an occluder within 2e-4 of the
   * distance from the light through (a floor 0.003 above a light 20 away) */
  ls->rel_margin = LC_REAL(0.0);
  return 1;
}

static inline float light_point_pdf(const lc_scene* s, __global const lc_light* L, lc_real3 p,
                                    float3 d, lc_real dist, float cos_l) {
  return 0.0f;
}

/* no surface */ static inline lc_real light_point_shadow_end(const lc_scene* s,
                                                              __global const lc_light* L,
                                                              lc_real3 o, lc_real3 d,
                                                              lc_real dist) {
  return dist;
}

static inline int light_point_seen_from(const lc_scene* s, __global const lc_light* L, lc_real3 o) {
  return 1;
}

static inline float3 light_point_emitted(const lc_scene* s, __global const lc_light* L, float3 d) {
  return (float3)(0.0f);
}

/* uniform directions: weight I / (1 / 4 pi) */
static inline int light_point_emit(const lc_scene* s, __global const lc_light* L, float4 u,
                                   lc_ray* ray, float3* beta) {
  ray->o = lc_load3r(L->p.point.position);
  ray->d = lc_real3_from_float3(sample_uniform_sphere(u.x, u.y));
  *beta = lc_load3(L->p.point.intensity) * (4.0f * LC_PI);
  return 1;
}
#endif
