/* lucent kernel: emissive triangles, sampled uniformly by area (in lc_real), one-sided: they emit
 * towards the side of (v1 - v0) x (v2 - v0). Parameters: lc_triangle_light_params (the triangle,
 * its material's emitted radiance, its area). */
#ifndef LUCENT_LIGHT_TRIANGLE_CL
#define LUCENT_LIGHT_TRIANGLE_CL

static inline int light_triangle_sample(const lc_scene* s, __global const lc_light* L, lc_real3 p,
                                        float u1, float u2, float u3, lc_light_sample* ls) {
  __global const lc_triangle* tri = &s->triangles[L->p.triangle.triangle];
  lc_real3 v0 = lc_load3ra(tri->v0), v1 = lc_load3ra(tri->v1), v2 = lc_load3ra(tri->v2);
  /* barycentrics in lc_real: in float their sum is off 1 by an ulp, which puts q ~1e-7 |v| off
   * the light's plane (covered by shadow_visible's float margin, not by its double one) */
  lc_real su = sqrt((lc_real)u1);
  lc_real b0 = LC_REAL(1.0) - su, b1 = u2 * su;
  lc_real3 q = b0 * v0 + b1 * v1 + (LC_REAL(1.0) - b0 - b1) * v2;
  lc_real3 nl = triangle_normal(tri, v0, v1, v2);
  lc_real3 to = q - p;
  lc_real d2 = dot(to, to);
  lc_real dist = sqrt(d2);
  if (!(dist > LC_REAL(0.0))) return 0;
  ls->wi = to / dist;
  lc_real cos_l = -dot(ls->wi, nl);
  if (cos_l <= LC_REAL(0.0)) return 0; /* one-sided emitter seen from behind */
  ls->dist = dist;
  ls->L = lc_load3(L->p.triangle.radiance);
  ls->pdf = L->pdf_select * d2 / (cos_l * L->p.triangle.area);
  /* stop short of this triangle by what the shadow ray can err about meeting it: q's rounding
   * and the ray's own triangle test, a few ulps of the coordinates involved, along the ray
   * (over cos_l); never more than the other lights' 2e-4 of dist, which let an occluder 1e-4 in
   * front of an emitting quad 2 away through */
  lc_real scale = lc_max3r(fmax(fmax(fabs(v0), fabs(v1)), fabs(v2))) + lc_max3r(fabs(p)) + dist;
  ls->rel_margin = fmin(LC_SHADOW_REL_MARGIN, LC_REAL(16.0) * LC_REAL_U * scale / (cos_l * dist));
  return 1;
}

static inline float light_triangle_pdf(const lc_scene* s, __global const lc_light* L, lc_real3 p,
                                       float3 d, lc_real dist, float cos_l) {
  if (cos_l > 0.0f) return L->pdf_select * dist * dist / (cos_l * L->p.triangle.area);
  return 0.0f;
}

/* flat: a segment from o to a point of it meets its plane there only */ static inline lc_real
light_triangle_shadow_end(const lc_scene* s, __global const lc_light* L, lc_real3 o, lc_real3 d,
                          lc_real dist) {
  return dist;
}

/* one-sided: seen from the front of its plane only */
static inline int light_triangle_seen_from(const lc_scene* s, __global const lc_light* L,
                                           lc_real3 o) {
  __global const lc_triangle* tri = &s->triangles[L->p.triangle.triangle];
  lc_real3 v0 = lc_load3ra(tri->v0), v1 = lc_load3ra(tri->v1), v2 = lc_load3ra(tri->v2);
  return dot(o - v0, triangle_normal(tri, v0, v1, v2)) > LC_REAL(0.0);
}

static inline float3 light_triangle_emitted(const lc_scene* s, __global const lc_light* L,
                                            float3 d) {
  return (float3)(0.0f);
}

/* a uniform point, a cosine-distributed direction on the front side: weight Le pi area */
static inline int light_triangle_emit(const lc_scene* s, __global const lc_light* L, float4 u,
                                      lc_ray* ray, float3* beta) {
  __global const lc_triangle* tri = &s->triangles[L->p.triangle.triangle];
  lc_real3 v0 = lc_load3ra(tri->v0), v1 = lc_load3ra(tri->v1), v2 = lc_load3ra(tri->v2);
  lc_real su = sqrt((lc_real)u.x);
  lc_real b0 = LC_REAL(1.0) - su, b1 = u.y * su, b2 = LC_REAL(1.0) - b0 - b1;
  lc_real3 q = b0 * v0 + b1 * v1 + b2 * v2;
  lc_real3 perr = triangle_point_error(b0, b1, b2, v0, v1, v2);
  lc_real3 nl = triangle_normal(tri, v0, v1, v2);
  lc_real3 t, b;
  lc_onbr(nl, &t, &b);
  float3 d = sample_cosine_hemisphere(u.z, u.w);
  ray->o = lc_spawn_origin(q, perr, nl);
  ray->d = normalize((lc_real)d.x * t + (lc_real)d.y * b + (lc_real)d.z * nl);
  *beta = lc_load3(L->p.triangle.radiance) * (LC_PI * L->p.triangle.area);
  return 1;
}
#endif
