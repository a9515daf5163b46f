/* lucent kernel: the closest hit and the surface interaction there: position, normals, texture
 * coordinates. Each shape type of shared/registry.h (LC_SHAPE_TYPES) has its file geom/<file>.cl
 * with its intersection test (used by bvh/traverse.cl) and
 *   void <file>_interaction(const lc_scene* s, lc_ray ray, const lc_hit* hit, lc_interaction* it)
 *     the surface at a hit on it: p, perr, ng, ns (not yet oriented), uv, material, light.
 * interaction_from_hit dispatches on the shape of the hit's primitive reference and orients the
 * normals towards the ray. */
#ifndef LUCENT_GEOM_INTERACTION_CL
#define LUCENT_GEOM_INTERACTION_CL

typedef struct {
  lc_real t;
  lc_uint prim;   /* primitive reference (LC_PRIM_SPHERE_BIT for spheres), LC_INVALID on a miss */
  lc_real b1, b2; /* triangle barycentrics of v1 and v2 */
} lc_hit;

/* Position, its error bound and the geometric normal are lc_real (double with --precision
 * double); the shading normal and texture coordinates, which only feed BSDFs and textures, are
 * float in both precisions. */
typedef struct {
  lc_real3 p;    /* hit position, recomputed from the primitive (not o + t d)            */
  lc_real3 perr; /* bound on the absolute error of p, per component                      */
  lc_real3 ng;   /* geometric normal, facing the incoming ray                            */
  float3 ns;     /* shading normal, on the same side as ng                               */
  float2 uv;     /* texture coordinates                                                  */
  lc_uint material;
  lc_uint light; /* light index if the primitive emits, else LC_INVALID                  */
  int front;     /* 1 when the ray hit the outside (the side the stored normal points to) */
} lc_interaction;

/* The shape type (LC_SHAPE_*) of a primitive reference. */
static inline lc_uint lc_prim_shape(lc_uint ref) {
  return (ref & LC_PRIM_SPHERE_BIT) ? LC_SHAPE_SPHERE : LC_SHAPE_TRIANGLE;
}

/* geom/<file>.cl for every shape type */
#include "generated/shapes.cl"

#define LC_SHAPE_INTERACTION(ID, Name, value, name, feature, file) \
  if (LC_ENABLED(feature) && shape == LC_SHAPE_##ID) file##_interaction(s, ray, hit, &it);
/* The surface at the hit, its normals not yet oriented (front unset). */
static inline lc_interaction interaction_surface(const lc_scene* s, lc_ray ray, const lc_hit* hit) {
  lc_interaction it;
  it.p = it.perr = it.ng = (lc_real3)(LC_REAL(0.0));
  it.ns = (float3)(0.0f);
  it.uv = (float2)(0.0f);
  it.material = 0;
  it.light = LC_INVALID;
  it.front = 1;
  lc_uint shape = lc_prim_shape(hit->prim);
  LC_SHAPE_TYPES(LC_SHAPE_INTERACTION)
  return it;
}

/* Orients a surface's normals towards a ray of direction d arriving at it: front is set, ng
 * faces the ray, ns is on its side (the geometric normal where the interpolated one faces away).
 * `it` must hold interaction_surface's normals, not already oriented ones. */
static inline void interaction_orient(lc_interaction* it, lc_real3 d) {
  it->front = dot(d, it->ng) < LC_REAL(0.0);
  if (!it->front) {
    it->ng = -it->ng;
    it->ns = -it->ns;
  }
  /* an interpolated normal facing away from the viewer: fall back to the geometric one */
  if (dot(lc_float3_from_real3(d), it->ns) >= 0.0f) it->ns = lc_float3_from_real3(it->ng);
}

static inline lc_interaction interaction_from_hit(const lc_scene* s, lc_ray ray,
                                                  const lc_hit* hit) {
  lc_interaction it = interaction_surface(s, ray, hit);
  interaction_orient(&it, ray.d);
  return it;
}

#undef LC_SHAPE_INTERACTION

#endif
