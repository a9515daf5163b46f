/* lucent test kernel: self-intersection of spawned rays (tests/test_stability_spawn.cpp).
 *
 * Each work item makes one hit point on one of the given primitives the way the renderer does
 * (a ray aimed at a random point of the surface, the real sphere_intersect / triangle_intersect,
 * then interaction_from_hit), spawns two rays from it with lc_spawn_origin, as the path
 * integrator does: one into the hemisphere of ng (reflection) and one into the opposite hemisphere
 * from the origin offset along -ng (transmission), and traces both against the same primitive with
 * the real intersection code (tmin = 0, as scene_intersect).
 *
 * A spawned ray leaving a triangle, or leaving a sphere on its convex (outer) side, must not hit
 * the primitive at all. A ray entering a sphere (the transmission side of an outside hit, the
 * reflection side of an inside hit) must hit the far side: a hit nearer than half the exact chord
 * 2 r |cos| is a self-hit, and no hit at all while the chord is longer than 1e-3 r is a missed
 * far side.
 *
 * Directions: cos to ng log-uniform in [1e-6, 1] (mostly grazing), uniform azimuth.
 * counters[0] hit points made   [1] rays traced          [2] self-hits
 *         [3] missed far sides   [4] generation misses (the aimed ray found no hit; skipped)
 * counters[5 + 8 k + 4 is_triangle + case]: per-case counts of self-hits (k = 0) and missed far
 * sides (k = 1); case = side + 2 inside (side 0: reflection, 1: transmission).
 * example: the last failure as (p, case + 4 is_triangle) and (direction, t).
 */
#define LC_HAS_SPHERES 1
#define LC_HAS_TRIANGLES 1
/* clang-format off */
#define LC_HAS_SPHERES 1
#define LC_HAS_TRIANGLES 1
#include "shared/types.h"
#include "shared/rng.h"
#include "util/math.cl"
#include "scene/scene.cl"
#include "geom/interaction.cl"
#include "bvh/traverse.cl"
/* clang-format on */

static inline float3 spawn_uniform_sphere(float u1, float u2) {
  float z = 1.0f - 2.0f * u1;
  float r = sqrt(fmax(0.0f, 1.0f - z * z));
  float phi = 2.0f * LC_PI * u2;
  return (float3)(r * cos(phi), r * sin(phi), z);
}

/* Direction around unit n with cos log-uniform in [1e-6, 1]. */
static inline float3 spawn_direction(float3 n, float u1, float u2) {
  float c = pow(10.0f, -6.0f * u1);
  float s = sqrt(fmax(0.0f, 1.0f - c * c));
  float phi = 2.0f * LC_PI * u2;
  float3 t, b;
  lc_onb(n, &t, &b);
  return normalize(s * cos(phi) * t + s * sin(phi) * b + c * n);
}

static inline lc_real spawn_trace(__global const lc_sphere* sp, __global const lc_triangle* tri,
                                  lc_real3 o, lc_real3 d) {
  if (sp) return sphere_intersect(lc_load3r(sp->center), sp->radius, o, d, 0.0f, INFINITY);
  lc_tri_ray tr = triangle_ray_setup(d);
  lc_real t, b1, b2;
  if (triangle_intersect(&tr, o, lc_load3r(tri->v0), lc_load3r(tri->v1), lc_load3r(tri->v2), 0.0f,
                         INFINITY, &t, &b1, &b2))
    return t;
  return INFINITY;
}

static inline void spawn_fail(__global int* counters, int which, __global float4* example, float3 p,
                              float kind, float3 d, float t) {
  atomic_inc(&counters[which]);
  /* per case: counters[5 + 8 (which - 2) + 4 is_triangle + kind] */
  atomic_inc(&counters[5 + 8 * (which - 2) + (int)kind]);
  example[0] = (float4)(p, kind);
  example[1] = (float4)(d, t);
}

__kernel void stability_spawn(__global const lc_sphere* spheres, lc_uint num_spheres,
                              __global const lc_triangle* triangles, lc_uint num_triangles,
                              lc_uint seed, __global int* counters, __global float4* example) {
  lc_uint i = (lc_uint)get_global_id(0);
  lc_uint prim = i % (num_spheres + num_triangles);
#define U(k) lc_rng_uniform(i, 0u, (k), seed)
  lc_scene s = lc_scene_geometry(0, 0, 0, triangles, spheres);

  lc_ray ray;
  lc_hit hit;
  __global const lc_sphere* sp = 0;
  __global const lc_triangle* tri = 0;
  float r = 0.0f;
  int inside = 0;
  if (prim < num_spheres) {
    sp = &spheres[prim];
    float3 c = lc_load3(sp->center);
    r = sp->radius;
    float3 u = spawn_uniform_sphere(U(0), U(1));
    if (U(2) < 0.5f) { /* from outside, aimed at a surface point, from 1e-3 r to 10 r away */
      float3 q = c + r * u;
      float3 w = u + spawn_uniform_sphere(U(3), U(4));
      float3 o = q + (r * pow(10.0f, -3.0f + 4.0f * U(5))) * normalize(w);
      ray.o = lc_real3_from_float3(o);
      ray.d = lc_real3_from_float3(normalize(q - o));
    } else { /* from inside */
      inside = 1;
      ray.o = lc_real3_from_float3(c + (0.99f * r * U(3)) * u);
      ray.d = lc_real3_from_float3(spawn_uniform_sphere(U(4), U(5)));
    }
    hit.t = sphere_intersect(lc_real3_from_float3(c), r, ray.o, ray.d, 0.0f, INFINITY);
    hit.prim = prim | LC_PRIM_SPHERE_BIT;
    hit.b1 = hit.b2 = 0.0f;
  } else {
    tri = &triangles[prim - num_spheres];
    float3 v0 = lc_load3(tri->v0), v1 = lc_load3(tri->v1), v2 = lc_load3(tri->v2);
    float su = sqrt(U(0));
    float b1 = U(1) * su, b0 = 1.0f - su;
    float3 q = b0 * v0 + b1 * v1 + (1.0f - b0 - b1) * v2;
    float size = length(v1 - v0) + length(v2 - v0);
    /* in lc_real: at 1e-30 (the double probe's smallest decade) the cross product of float edges
     * underflows to 0, and normalize(0) is 0 on PoCL but NaN on Intel's CPU runtime */
    lc_real3 e1 = lc_real3_from_float3(v1 - v0), e2 = lc_real3_from_float3(v2 - v0);
    float3 n = lc_float3_from_real3(normalize(cross(e1, e2)));
    if (U(2) < 0.5f) n = -n;
    float3 w = n + spawn_uniform_sphere(U(3), U(4));
    float3 o = q + (size * pow(10.0f, -3.0f + 4.0f * U(5))) * normalize(w);
    ray.o = lc_real3_from_float3(o);
    ray.d = lc_real3_from_float3(normalize(q - o));
    lc_tri_ray tr = triangle_ray_setup(ray.d);
    hit.t = INFINITY;
    if (!triangle_intersect(&tr, ray.o, lc_real3_from_float3(v0), lc_real3_from_float3(v1),
                            lc_real3_from_float3(v2), 0.0f, INFINITY, &hit.t, &hit.b1, &hit.b2))
      hit.t = INFINITY;
    hit.prim = prim - num_spheres;
  }
  if (!(hit.t < INFINITY)) {
    atomic_inc(&counters[4]);
    return;
  }
  atomic_inc(&counters[0]);
  lc_interaction it = interaction_from_hit(&s, ray, &hit);
  /* an origin meant to be just outside may round to inside a small sphere: what counts is the
   * side the renderer sees */
  inside = !it.front;

  for (int side = 0; side < 2; ++side) {
    lc_real3 n = side == 0 ? it.ng : -it.ng;
    lc_real3 o = lc_spawn_origin(it.p, it.perr, n);
    float3 dir = spawn_direction(lc_float3_from_real3(n), U(6 + 2 * side), U(7 + 2 * side));
    lc_real3 d = lc_real3_from_float3(dir);
#ifdef LC_DOUBLE
    d = normalize(d); /* unit in double, as the renderer's directions */
#endif
    if (!(dot(d, n) > 0.0f)) continue; /* the renderer drops such directions */
    atomic_inc(&counters[1]);
    lc_real t = spawn_trace(sp, tri, o, d);
    /* into the sphere: the reflection side of an inside hit, the transmission side of an
     * outside hit */
    int enters = sp && (inside ? side == 0 : side == 1);
    float kind = (float)(side + 2 * inside + (tri ? 4 : 0));
    float3 pf = lc_float3_from_real3(it.p), df = lc_float3_from_real3(d);
    if (!enters) {
      if (t < INFINITY) spawn_fail(counters, 2, example, pf, kind, df, t);
    } else {
      lc_real chord = 2.0f * r * dot(d, n);
      if (t < 0.5f * chord)
        spawn_fail(counters, 2, example, pf, kind, df, t);
      else if (!(t < INFINITY) && chord > 1e-3f * r)
        spawn_fail(counters, 3, example, pf, kind, df, t);
    }
  }
#undef U
}

/* lc_step_along (util/math.cl), lc_spawn_origin's one-ulp step: in[2i] = o, in[2i + 1] = n (w
 * unused); out[i] = lc_step_along(o, n), which the host checks against nextafter
 * (tests/test_stability_spawn.cpp, SpawnStep). */
#ifdef LC_DOUBLE
typedef double4 spawn_real4;
#else
typedef float4 spawn_real4;
#endif
__kernel void probe_spawn_step(__global const spawn_real4* in, __global spawn_real4* out) {
  size_t i = get_global_id(0);
  out[i] = (spawn_real4)(lc_step_along(in[2 * i].xyz, in[2 * i + 1].xyz), LC_REAL(0.0));
}
