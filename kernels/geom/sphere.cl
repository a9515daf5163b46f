/* lucent kernel: ray/sphere intersection that stays precise far from the origin and for small
 * spheres far from the ray origin (Haines et al., "Precision Improvements for Ray/Sphere
 * Intersection", Ray Tracing Gems ch. 7). The ray direction is unit length. The discriminant
 * r^2 - |l|^2 (l: centre to its closest point on the ray line) and the root pair c / q, q avoid the
 * cancellation of b^2 - c; tests/test_bvh_trace.cpp (SphereSets: spheres of radius 0.5-2 at 1e5
 * from the origin) fails with the textbook b^2 - c form. */
#ifndef LUCENT_GEOM_SPHERE_CL
#define LUCENT_GEOM_SPHERE_CL

#include "texture/texture.cl"

/* Returns the nearest t in (tmin, tmax) or INFINITY. */
static inline lc_real sphere_intersect(lc_real3 center, lc_real radius, lc_real3 o, lc_real3 d,
                                       lc_real tmin, lc_real tmax) {
  lc_real3 f = o - center;
  lc_real b = -dot(f, d);
  /* discriminant from the distance of the centre to the ray line: no catastrophic cancellation */
  lc_real3 l = f + b * d;
  lc_real r2 = radius * radius;
  lc_real disc = r2 - dot(l, l);
  if (disc < LC_REAL(0.0)) return INFINITY;
  lc_real c = dot(f, f) - r2;
  lc_real q = b + copysign(sqrt(disc), b);
  lc_real t0 = c / q;
  lc_real t1 = q;
  if (t0 > t1) {
    lc_real tmp = t0;
    t0 = t1;
    t1 = tmp;
  }
  if (t0 > tmin && t0 < tmax) return t0;
  if (t1 > tmin && t1 < tmax) return t1;
  return INFINITY;
}

/* The bound on the absolute error of a point of the sphere (centre c, radius r), per component:
 * a few ulps of |c| + r, the representation limit (in lc_real) of its surface. Shared by hits
 * (sphere_interaction) and emitted points (light/sphere.cl). */
static inline lc_real3 sphere_point_error(lc_real3 c, lc_real r) {
  return (fabs(c) + r) * (LC_REAL(8.0) * LC_REAL_U);
}

/* The surface at a hit on a sphere. */
static inline void sphere_interaction(const lc_scene* s, lc_ray ray, const lc_hit* hit,
                                      lc_interaction* it) {
  __global const lc_sphere* sp = &s->spheres[hit->prim & ~LC_PRIM_SPHERE_BIT];
  lc_real3 c = lc_load3r(sp->center);
  lc_real3 p = ray.o + hit->t * ray.d;
  lc_real3 n = normalize(p - c);
  it->p = c + sp->radius * n; /* reproject onto the surface */
  it->perr = sphere_point_error(c, sp->radius);
  it->ng = n;
  float3 nf = lc_float3_from_real3(n);
  it->ns = nf;
  /* equirectangular uv: u along longitude around +y, eastward (to the right seen from outside,
   * the image's centre at +z: atan2(z, x) mirrored it), v from the south to the north pole; only
   * textures read it (atan2 and asin cost ~8% of a scene of large untextured spheres), in the
   * texture space of its material's texture (texture_map_uv) */
#ifdef LC_HAS_TEXTURES
  if (sp->flags & LC_SPHERE_TEXTURED)
    it->uv = texture_map_uv(s, (int)sp->texture,
                            (float2)(0.5f + atan2(nf.x, nf.z) * (0.5f * LC_INV_PI),
                                     0.5f + asin(clamp(nf.y, -1.0f, 1.0f)) * LC_INV_PI));
#endif
  it->material = sp->material;
  it->light = sp->light;
}

#endif
