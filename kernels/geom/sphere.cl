/* lucent kernel: ray/sphere intersection that stays precise far from the origin and for small
 * spheres far from the ray origin (Haines et al., "Precision Improvements for Ray/Sphere
 * Intersection", Ray Tracing Gems ch. 7). The ray direction is unit length. The discriminant
 * r^2 - |l|^2 (l: centre to its closest point on the ray line) and the root pair c / q, q avoid the
 * cancellation of b^2 - c; tests/test_bvh_trace.cpp (SphereSets: spheres of radius 0.5-2 at 1e5
 * from the origin) fails with the textbook b^2 - c form. */
#ifndef LUCENT_GEOM_SPHERE_CL
#define LUCENT_GEOM_SPHERE_CL

/* Returns the nearest t in (tmin, tmax) or INFINITY. */
static inline float sphere_intersect(float3 center, float radius, float3 o, float3 d, float tmin,
                                     float tmax) {
  float3 f = o - center;
  float b = -dot(f, d);
  /* discriminant from the distance of the centre to the ray line: no catastrophic cancellation */
  float3 l = f + b * d;
  float r2 = radius * radius;
  float disc = r2 - dot(l, l);
  if (disc < 0.0f) return INFINITY;
  float c = dot(f, f) - r2;
  float q = b + copysign(sqrt(disc), b);
  float t0 = c / q;
  float t1 = q;
  if (t0 > t1) {
    float tmp = t0;
    t0 = t1;
    t1 = tmp;
  }
  if (t0 > tmin && t0 < tmax) return t0;
  if (t1 > tmin && t1 < tmax) return t1;
  return INFINITY;
}

#endif
