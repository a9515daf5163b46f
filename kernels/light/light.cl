/* lucent kernel: light sampling for next-event estimation, and the matching pdfs for MIS.
 * Lights are chosen by lc_light.pdf_select (cumulative in light_cdf; src/render/lights.cpp
 * sets them: 90% by power, 10% uniform). Each light type of shared/registry.h (LC_LIGHT_TYPES)
 * has its file light/<file>.cl defining
 *   int    light_<file>_sample(const lc_scene* s, __global const lc_light* L, lc_real3 p,
 *                              float u1, float u2, float u3, lc_light_sample* ls)
 *            a direction from p towards the light, its radiance and pdf (selection included);
 *            u1, u2 a pair (a point on the light), u3 a number for lights that need a third
 *            (an environment map: u1 chooses the texel, u3 and u2 the point inside it)
 *   float  light_<file>_pdf(const lc_scene* s, __global const lc_light* L, lc_real3 p, float3 d,
 *                           lc_real dist, float cos_l)
 *            the solid-angle pdf (selection included) with which _sample from p produces the
 *            direction d meeting the light at distance dist from p with light-side cosine cos_l
 *            (dist 0: p is behind the light's plane, where _sample gives nothing)
 *   lc_real light_<file>_shadow_end(const lc_scene* s, __global const lc_light* L, lc_real3 o,
 *                                   lc_real3 d, lc_real dist)
 *            where a shadow ray from o along d towards a sampled point at distance dist meets the
 *            light's own surface first: dist, unless the light can hide its sampled point from o
 *            (a sphere light: o lies off the surface point that sampled it, and from there a
 *            point near the silhouette can be on the far side)
 *   int    light_<file>_seen_from(const lc_scene* s, __global const lc_light* L, lc_real3 o)
 *            whether a ray from o can meet the light's emitting side: 0 for o inside a sphere
 *            light or not in front of a triangle light's plane (where a surface's offset origin
 *            lands when the lamp nearly touches it), so BSDF sampling from o never reaches it
 *   float3 light_<file>_emitted(const lc_scene* s, __global const lc_light* L, float3 d)
 *            radiance of a ray escaping the scene in direction d (environments; 0 for others,
 *            whose emission is their material's)
 *   int    light_<file>_emit(const lc_scene* s, __global const lc_light* L, float4 u,
 *                            lc_ray* ray, float3* beta)
 *            light tracing (integrator/caustics.cl): a ray leaving the light and its weight
 *            Le |cos| / (p_A p_w), or I / p_w for point lights (selection not included); 0 for
 *            lights that start no light paths (environments)
 * Every type's file is included (generated/lights.cl); the dispatch compiles a type's branch
 * only when its feature define is set. */
#ifndef LUCENT_LIGHT_LIGHT_CL
#define LUCENT_LIGHT_LIGHT_CL

/* Relative shortening of shadow rays towards a light's surface (integrator/common.cl,
 * shadow_visible), unless a light type bounds it better: float's 2e-4, and for double about
 * 2e-4 times the ratio of the two epsilons (3.7e-13), rounded up. The sampled light point must
 * then be computed in lc_real throughout (the light/ files): a float barycentric sum or a
 * float sin/cos pair puts it ~1e-7 off the light's surface, which this margin does not cover
 * (the Cornell box's NEE was 15% too dark in double until they were lc_real). */
#ifdef LC_DOUBLE
#define LC_SHADOW_REL_MARGIN 1e-12
#else
#define LC_SHADOW_REL_MARGIN 2e-4f
#endif

typedef struct {
  lc_real3 wi;        /* unit direction towards the light                          */
  lc_real dist;       /* distance to the sampled point (INFINITY for environments) */
  float3 L;           /* radiance arriving (I / r^2 for point lights)              */
  float pdf;          /* solid-angle pdf including the selection probability;
                         for point lights the selection probability                */
  int delta;          /* point light: no MIS                                        */
  lc_real rel_margin; /* how far short of dist, relative to it, the shadow ray stops:
                         LC_SHADOW_REL_MARGIN unless the light type knows better (0 for a
                         point light, which has no surface; a triangle light's own bound) */
  lc_uint light;      /* the light sampled (light_shadow_end)                       */
} lc_light_sample;

/* Index i with cdf[i-1] <= u < cdf[i] over n entries (cdf[n-1] = 1): the number of entries
 * <= u, at most n - 1. A binary search whose steps depend on n alone (the halves are chosen by a
 * select, not a branch that a random u mispredicts). */
static inline lc_uint lc_cdf_search(__global const float* cdf, lc_uint n, float u) {
  lc_uint base = 0, len = n;
  while (len > 1) {
    lc_uint step = len >> 1;
    base = cdf[base + step] <= u ? base + step : base;
    len -= step;
  }
  return min(base + (cdf[base] <= u ? 1u : 0u), n - 1u);
}

static inline float3 sample_uniform_sphere(float u1, float u2) {
  float z = 1.0f - 2.0f * u1;
  float r = sqrt(fmax(0.0f, 1.0f - z * z));
  return (float3)(r * lc_unit_circle(u2), z);
}

/* light/<file>.cl for every light type */
#include "generated/lights.cl"

/* ---- dispatch ---- */

#define LC_LIGHT_EMITTED(ID, Name, value, name, feature, file, params)                     \
  if (LC_ENABLED(feature) && L->type == LC_LIGHT_##ID) {                                   \
    *pdf = light_##file##_pdf(s, L, (lc_real3)(LC_REAL(0.0)), d, (lc_real)INFINITY, 1.0f); \
    return light_##file##_emitted(s, L, d);                                                \
  }
/* Radiance of a ray escaping the scene in direction d, and the pdf (with selection) with which
 * light sampling would have produced d. */
static inline float3 env_radiance(const lc_scene* s, float3 d, float* pdf) {
  __global const lc_params* P = s->params;
  *pdf = 0.0f;
  if (P->env_light < 0) return (float3)(0.0f);
  __global const lc_light* L = &s->lights[P->env_light];
  LC_LIGHT_TYPES(LC_LIGHT_EMITTED)
  return (float3)(0.0f);
}
#undef LC_LIGHT_EMITTED

#define LC_LIGHT_PDF(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && L->type == LC_LIGHT_##ID)             \
    return light_##file##_pdf(s, L, p, d, dist, cos_l);
/* Solid-angle pdf (with selection) that light sampling from p picks the point seen along d on
 * light `light` at distance dist with light-side cosine cos_l (> 0): MIS for an emitter hit. */
static inline float light_pdf(const lc_scene* s, lc_uint light, lc_real3 p, float3 d, lc_real dist,
                              float cos_l) {
  __global const lc_light* L = &s->lights[light];
  LC_LIGHT_TYPES(LC_LIGHT_PDF)
  return 0.0f;
}
#undef LC_LIGHT_PDF

#define LC_LIGHT_SAMPLE(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && L->type == LC_LIGHT_##ID)                \
    return light_##file##_sample(s, L, p, u1, u2, u3, ls);
/* Chooses a light with us and samples it with u1, u2, u3 from the shading point p itself (as
 * pbrt-v4's LightSampleContext does), and the integrator's shadow ray goes from its offset origin
 * to the sampled point (integrator/path.cl). Sampled from that origin instead, an area light lit
 * the surface as it lights a point an offset above it: a relative bias of about
 * offset (3 cos^2 phi - 1) / h for a light at height h and angle phi off the normal, +1% for a
 * small lamp 0.01 over a floor of +-60 in float (RenderAnalytic.AreaLightsLightTheSurfacePoint),
 * and a point light 32% too bright over a ground sphere of radius 1e5. Choosing light `self`
 * (the shading point's own emitter, LC_INVALID for none) gives no sample: an emitter never
 * lights its own surface (a sphere is convex, a triangle flat), and from a point on (or, by
 * rounding, just outside) a sphere light its cone is almost a hemisphere: an emissive rough
 * glass sphere took those samples through its own back face, up to 25% too bright. */
static inline int light_sample(const lc_scene* s, lc_real3 p, lc_uint self, float us, float u1,
                               float u2, float u3, lc_light_sample* ls) {
  __global const lc_params* P = s->params;
  if (P->num_lights == 0) return 0;
  lc_uint li = lc_cdf_search(s->light_cdf, P->num_lights, us);
  __global const lc_light* L = &s->lights[li];
  if (li == self) return 0;
  ls->delta = 0;
  ls->rel_margin = LC_SHADOW_REL_MARGIN;
  ls->light = li;
  LC_LIGHT_TYPES(LC_LIGHT_SAMPLE)
  return 0;
}
#undef LC_LIGHT_SAMPLE

#define LC_LIGHT_SEEN_FROM(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && L->type == LC_LIGHT_##ID) return light_##file##_seen_from(s, L, o);
/* Whether BSDF-sampled rays from o can reach the emitting side of the light of sample ls
 * (integrator/path.cl: if not, the light sample is the only strategy for that light). */
static inline int light_seen_from(const lc_scene* s, const lc_light_sample* ls, lc_real3 o) {
  __global const lc_light* L = &s->lights[ls->light];
  LC_LIGHT_TYPES(LC_LIGHT_SEEN_FROM)
  return 1;
}
#undef LC_LIGHT_SEEN_FROM

#define LC_LIGHT_SHADOW_END(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && L->type == LC_LIGHT_##ID)                    \
    return light_##file##_shadow_end(s, L, o, d, dist);
/* How far a shadow ray from o along d may go towards the point of light sample ls at distance
 * dist from o before it meets that light's own surface (integrator/common.cl,
 * shadow_visible_sample). */
static inline lc_real light_shadow_end(const lc_scene* s, const lc_light_sample* ls, lc_real3 o,
                                       lc_real3 d, lc_real dist) {
  __global const lc_light* L = &s->lights[ls->light];
  LC_LIGHT_TYPES(LC_LIGHT_SHADOW_END)
  return dist;
}
#undef LC_LIGHT_SHADOW_END

#define LC_LIGHT_EMIT(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && L->type == LC_LIGHT_##ID) ok = light_##file##_emit(s, L, u, ray, beta);
/* Chooses a light with us (the next-event selection) and starts a light path on it with u: the
 * ray and its weight, the selection probability included. */
static inline int light_emit(const lc_scene* s, float us, float4 u, lc_ray* ray, float3* beta) {
  __global const lc_params* P = s->params;
  if (P->num_lights == 0) return 0;
  __global const lc_light* L = &s->lights[lc_cdf_search(s->light_cdf, P->num_lights, us)];
  int ok = 0;
  LC_LIGHT_TYPES(LC_LIGHT_EMIT)
  if (!ok || !(L->pdf_select > 0.0f)) return 0;
  *beta /= L->pdf_select;
  return 1;
}
#undef LC_LIGHT_EMIT

#endif
