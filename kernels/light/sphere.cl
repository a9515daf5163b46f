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
  /* angle alpha at the sphere centre between -d and the sampled point; x = (sin t / sin tmax)^2 */
  lc_real x = fmin(sin2t / sin2max, LC_REAL(1.0));
  lc_real k = sqrt(LC_REAL(1.0) - x);
  lc_real cos_a = clamp(sin2t / sqrt(sin2max) + cos_t * k, LC_REAL(-1.0), LC_REAL(1.0));
  /* sin alpha without sqrt(1 - cos_a^2), which cancels where alpha is small (a large sphere
   * seen from nearby: the sampled points cluster at its centre's foot, and in float a floor 0.5
   * under a sphere light of radius 4000 was lit 28% too bright, of radius 1e4 38%): by the law of
   * sines, alpha = asin(sqrt(x)) - t, so sin alpha = sqrt(x) cos t - k sin t, and times its
   * conjugate over it, sqrt(x) cos^2 tmax / (cos t + sin tmax k), every term positive */
  lc_real sin_a = sqrt(x) * (LC_REAL(1.0) - sin2max) / (cos_t + sqrt(sin2max) * k);
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
  /* q is known to the sphere's ulps only (sphere_point_error), and so is where the shadow ray
   * meets the light itself: stop short of it by a few of them, along the ray (over cos_l, as a
   * triangle light does), never by less than 4 of them (a floor 0.5 under a sphere light of
   * radius 4000, ulps of 2.4e-4, lost a tenth of its light to the light's own surface with a
   * relative margin alone) nor, grazing, by more than the other lights' 2e-4 of dist. That fixed
   * 2e-4 let through an occluder within it of the light: a lamp of radius 600 poking 0.27 through
   * a ceiling, lit 80 away, showed 0.016 more of itself, +6% of its direct light (the
   * smallpt-style room 0.8% bright with walls of triangles). Such an occluder within the few
   * ulps is let through: float cannot tell it from the surface anyway. */
  const lc_real ulps = LC_REAL(4.0) * lc_max3r(sphere_point_error(c, r));
  const lc_real cos_l = -dot(ls->wi, n);
  const lc_real along = ulps + LC_REAL(16.0) * LC_REAL_U * (lc_max3r(fabs(p)) + dist);
  ls->rel_margin = fmax(ulps / dist, cos_l > LC_REAL(0.0) ? fmin((lc_real)LC_SHADOW_REL_MARGIN,
                                                                 along / (cos_l * dist))
                                                          : (lc_real)LC_SHADOW_REL_MARGIN);
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

/* The sphere's first point along the shadow ray. The sample's point q is on the part of the sphere
 * that the surface point p sees, but the shadow ray leaves from o, off the surface, and from o a
 * point near the silhouette seen from p can lie on the far side: the ray from o to q then enters
 * the lamp before q and the lamp shadowed itself. Over a ground sphere of radius 3e5 (offsets of
 * 0.1 in float) a lamp 2 above lit the floor 1.6% too dark, and with offsets above the lamp (radius
 * 1e6) 73% too dark (RenderAnalytic.SphereLightOverAHugeGroundSphere). The shadow ray stops
 * where it meets the lamp, found as traversal will find it. */
static inline lc_real light_sphere_shadow_end(const lc_scene* s, __global const lc_light* L,
                                              lc_real3 o, lc_real3 d, lc_real dist) {
  __global const lc_sphere* sp = &s->spheres[L->p.sphere.sphere];
  return fmin(dist, sphere_intersect(lc_load3r(sp->center), sp->radius, o, d, LC_REAL(0.0), dist));
}

/* from outside only: it emits outwards */
static inline int light_sphere_seen_from(const lc_scene* s, __global const lc_light* L,
                                         lc_real3 o) {
  __global const lc_sphere* sp = &s->spheres[L->p.sphere.sphere];
  lc_real3 d = o - lc_load3r(sp->center);
  lc_real r = sp->radius;
  return dot(d, d) > r * r;
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
