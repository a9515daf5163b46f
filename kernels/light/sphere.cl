/* lucent kernel: emissive spheres, sampled by the cone they subtend from the shading point
 * (pbrt-v4's Sphere::Sample), in lc_real. Parameters: lc_sphere_light_params (the sphere, its
 * material's emitted radiance). */
#ifndef LUCENT_LIGHT_SPHERE_CL
#define LUCENT_LIGHT_SPHERE_CL

static inline int light_sphere_sample(const lc_scene* s, __global const lc_light* L, lc_real3 p,
                                      float u1, float u2, float u3, lc_light_sample* ls) {
  __global const lc_sphere* sp = &s->spheres[L->p.sphere.sphere];
  lc_real3 c = lc_load3r(sp->center);
  lc_real r = sp->radius;
  lc_real3 d = c - p;
  lc_real dc2 = dot(d, d);
  if (dc2 <= r * r) return 0; /* inside: the emitting side faces away */
  lc_real dc = sqrt(dc2);
  lc_real sin2max = r * r / dc2;
  lc_real cosmax = sqrt(fmax(LC_REAL(0.0), LC_REAL(1.0) - sin2max));
  lc_real one_minus_cosmax = sin2max / (LC_REAL(1.0) + cosmax);
  /* cone sampling, precise for tiny cones */
  lc_real one_minus_cos_t = one_minus_cosmax * u1;
  lc_real cos_t = LC_REAL(1.0) - one_minus_cos_t;
  lc_real sin2t = one_minus_cos_t * (LC_REAL(2.0) - one_minus_cos_t);
  /* angle alpha at the sphere centre between -d and the sampled point */
  lc_real cos_a =
      sin2t / sqrt(sin2max) + cos_t * sqrt(fmax(LC_REAL(0.0), LC_REAL(1.0) - sin2t / sin2max));
  cos_a = clamp(cos_a, LC_REAL(-1.0), LC_REAL(1.0));
  lc_real sin_a = sqrt(fmax(LC_REAL(0.0), LC_REAL(1.0) - cos_a * cos_a));
  /* phi's sine and cosine in lc_real: in float |n| is 1 only to a float ulp, which puts q
   * ~1e-7 r off the sphere (covered by shadow_visible's float margin, not by its double one) */
  lc_real2 cs = sin_a * lc_unit_circler((lc_real)u2);
  lc_real3 wc = -d / dc; /* from the centre towards p */
  lc_real3 t, b;
  lc_onbr(wc, &t, &b);
  lc_real3 n = cs.x * t + cs.y * b + cos_a * wc;
  lc_real3 q = c + r * n;
  lc_real3 to = q - p;
  lc_real dist = length(to);
  if (!(dist > LC_REAL(0.0))) return 0;
  ls->wi = to / dist;
  ls->dist = dist;
  ls->L = lc_load3(L->p.sphere.radiance);
  ls->pdf = L->pdf_select / (2.0f * LC_PI * one_minus_cosmax);
  return 1;
}

/* the cone's uniform density, whatever point of the sphere d meets */
static inline float light_sphere_pdf(const lc_scene* s, __global const lc_light* L, lc_real3 p,
                                     float3 dir, lc_real dist, float cos_l) {
  __global const lc_sphere* sp = &s->spheres[L->p.sphere.sphere];
  lc_real3 d = lc_load3r(sp->center) - p;
  lc_real r = sp->radius;
  lc_real dc2 = dot(d, d), r2 = r * r;
  if (dc2 <= r2) return 0.0f;
  lc_real sin2 = r2 / dc2;
  lc_real cosmax = sqrt(fmax(LC_REAL(0.0), LC_REAL(1.0) - sin2));
  lc_real one_minus = sin2 / (LC_REAL(1.0) + cosmax);
  return L->pdf_select / (2.0f * LC_PI * one_minus);
}

static inline float3 light_sphere_emitted(const lc_scene* s, __global const lc_light* L, float3 d) {
  return (float3)(0.0f);
}

/* a uniform point of the sphere, a cosine-distributed direction about its outward normal:
 * weight Le cos / (1 / area * cos / pi) = Le pi area */
static inline int light_sphere_emit(const lc_scene* s, __global const lc_light* L, float4 u,
                                    lc_ray* ray, float3* beta) {
  __global const lc_sphere* sp = &s->spheres[L->p.sphere.sphere];
  lc_real3 c = lc_load3r(sp->center);
  lc_real r = sp->radius;
  lc_real3 n = normalize(lc_real3_from_float3(sample_uniform_sphere(u.x, u.y)));
  lc_real3 perr = sphere_point_error(c, r);
  lc_real3 t, b;
  lc_onbr(n, &t, &b);
  float3 d = sample_cosine_hemisphere(u.z, u.w);
  ray->o = lc_spawn_origin(c + r * n, perr, n);
  ray->d = normalize((lc_real)d.x * t + (lc_real)d.y * b + (lc_real)d.z * n);
  *beta = lc_load3(L->p.sphere.radiance) * (float)(LC_PI * 4.0f * LC_PI * r * r);
  return 1;
}
#endif
