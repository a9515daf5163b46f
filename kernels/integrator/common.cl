/* lucent kernel: what several integrators share: MIS weights, the shading frame, shadow rays and
 * point-light illumination. */
#ifndef LUCENT_INTEGRATOR_COMMON_CL
#define LUCENT_INTEGRATOR_COMMON_CL

/* Power heuristic with beta = 2. */
static inline float mis_power(float a, float b) {
  /* a^2 / (a^2 + b^2) as 1 / (1 + (b/a)^2): the squares of pdfs above 1.8e19 (a sphere light
   * subtending 1e-10 rad) overflowed float, and inf / inf made nearly every lit sample NaN */
  if (isinf(a)) return 1.0f;
  if (!(a > 0.0f)) return 0.0f;
  float r = b / a;
  return 1.0f / (1.0f + r * r);
}

/* Local shading frame around n. */
typedef struct {
  float3 t, b, n;
} lc_frame;
static inline lc_frame frame_from(float3 n) {
  lc_frame f;
  f.n = n;
  lc_onb(n, &f.t, &f.b);
  return f;
}
static inline float3 frame_to_local(const lc_frame* f, float3 v) {
  return (float3)(dot(v, f->t), dot(v, f->b), dot(v, f->n));
}
static inline float3 frame_to_world(const lc_frame* f, float3 v) {
  return v.x * f->t + v.y * f->b + v.z * f->n;
}

/* A direction of the shading frame (a sampled or mirrored one) as the world-space direction of
 * the next ray. In float it is not normalised again: the frame is orthonormal and the direction
 * unit to a few ulps, so the result is unit to about 1e-7, and every cosine taken from it is
 * clamped where a square root or an arccosine follows (pbrt-v4 and Mitsuba 3 do the same). The
 * normalize() it replaced put a square root and a division on the way to the next ray's
 * traversal: 1.058x on the Cornell box, 1.039x on the dragon box (BENCHMARKS.md, "Directions
 * not normalised again"). Under LC_DOUBLE it is normalised in double, so that rays stay unit to
 * double precision. */
static inline lc_real3 frame_to_world_dir(const lc_frame* f, float3 v) {
#ifdef LC_DOUBLE
  return normalize(lc_real3_from_float3(frame_to_world(f, v)));
#else
  return frame_to_world(f, v);
#endif
}

/* Unoccluded test from a spawned origin o along wi, up to distance dist from o (a sampled light
 * point; INFINITY for an environment). Lights are sampled from the surface point
 * (light/light.cl), and their shadow rays go from o to the sampled point (shadow_visible_sample).
 * rel_margin: the light sample's (lc_light_sample.rel_margin, light/light.cl): how far short
 * of the sampled point, relative to dist, the ray stops. */
static inline int shadow_visible(const lc_scene* s, lc_real3 o, lc_real3 wi, lc_real dist,
                                 lc_real rel_margin, lc_uint* rays) {
  lc_ray sr;
  sr.o = o;
  sr.d = wi;
  ++*rays;
  /* stop short of the light's own surface by its position error: relative to the distance, and
   * a few ulps of the sampled point's coordinates (it is only known to those: at 1e4 from the
   * origin a point on a sphere light 2 away is 1e-3 off, 2.5 times 2e-4 dist, and the shadow ray
   * hit the light itself: 20% too dark, tests/test_stability_scene.cpp StabilityTranslateLight);
   * both margins scale with lc_real's precision */
  lc_real tmax = isinf(dist) ? (lc_real)INFINITY
                             : dist * (LC_REAL(1.0) - rel_margin) -
                                   LC_REAL(8.0) * LC_REAL_EPSILON * (lc_max3r(fabs(o)) + dist);
  return !scene_occluded(s, sr, tmax);
}

/* Unoccluded test from a spawned origin o towards the sampled light point q. */
static inline int shadow_visible_to(const lc_scene* s, lc_real3 o, lc_real3 q, lc_real rel_margin,
                                    lc_uint* rays) {
  lc_real3 to = q - o;
  lc_real dist = length(to);
  if (!(dist > LC_REAL(0.0))) return 0;
  return shadow_visible(s, o, to / dist, dist, rel_margin, rays);
}

/* Unoccluded test of light sample ls, drawn from the surface point p, from the shadow ray's origin
 * o (in front of the surface, or behind it for a transmitting BSDF): towards the sampled point,
 * up to where the light's own surface comes first (light_shadow_end), or along the direction
 * for an environment. */
static inline int shadow_visible_sample(const lc_scene* s, lc_real3 o, lc_real3 p,
                                        const lc_light_sample* ls, lc_uint* rays) {
  if (isinf(ls->dist)) return shadow_visible(s, o, ls->wi, ls->dist, ls->rel_margin, rays);
  lc_real3 to = p + ls->dist * ls->wi - o;
  lc_real dist = sqrt(dot(to, to)); /* as the light files measure their samples' distances */
  if (!(dist > LC_REAL(0.0))) return 0;
  lc_real3 d = to / dist;
  return shadow_visible(s, o, d, light_shadow_end(s, ls, o, d, dist), ls->rel_margin, rays);
}

/* Sum over point lights of f * cos * I / r^2 (direct and whitted integrators): f is the BSDF b,
 * or when b is null the lambertian diffuse / pi (whitted's diffuse term). */
static inline float3 point_lights_direct(const lc_scene* s, const lc_interaction* it,
                                         const lc_bsdf* b, float3 diffuse, const lc_frame* fr,
                                         float3 wo_l, lc_uint* rays) {
  float3 sum = (float3)(0.0f);
#ifdef LC_HAS_POINT_LIGHTS
  __global const lc_params* P = s->params;
  for (lc_uint i = 0; i < P->num_lights; ++i) {
    __global const lc_light* L = &s->lights[i];
    if (L->type != LC_LIGHT_POINT) continue;
    /* irradiance from the surface point itself; the shadow ray leaves from the offset origin
     * (a point light has no surface that the few-ulp parallel shift could graze), behind the
     * surface for a light behind a transmitting BSDF */
    lc_real3 to = lc_load3r(L->p.point.position) - it->p;
    lc_real d2 = dot(to, to);
    lc_real dist = sqrt(d2);
    lc_real3 wi = to / dist;
    int behind = !(dot(wi, it->ng) > LC_REAL(0.0));
    if (behind && !(b && (bsdf_lobes(b) & LC_BSDF_TRANSMISSION))) continue;
    lc_real3 o = lc_spawn_origin(it->p, it->perr, behind ? -it->ng : it->ng);
    float3 wi_l = frame_to_local(fr, lc_float3_from_real3(wi));
    if (behind ? wi_l.z >= 0.0f : wi_l.z <= 0.0f) continue;
    float3 f;
    if (!b) {
      f = diffuse * LC_INV_PI;
    } else {
      float pdf;
      f = bsdf_eval(b, wo_l, wi_l, &pdf);
    }
    if (lc_max3(f) <= 0.0f) continue;
    /* from o to the light, stopping short by shadow_visible's margin, as the path integrator's
     * shadow ray does: a ray to the full distance from the surface point met the surface a light
     * lies on (a point light at ceiling height: the floor lost 43% of its light, and a light in
     * a quad's plane lit nothing) */
    if (!shadow_visible_to(s, o, lc_load3r(L->p.point.position), LC_REAL(0.0), rays)) continue;
    sum += f * lc_load3(L->p.point.intensity) * (fabs(wi_l.z) / (float)d2);
  }
#endif
  return sum;
}

#endif
