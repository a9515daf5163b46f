/* lucent kernel: watertight ray/triangle intersection (Woop, Benthin and Wald, "Watertight
 * Ray/Triangle Intersection", JCGT 2(1), 2013). The ray is sheared and scaled so that it runs
 * along +z through the origin; the 2D edge functions U, V, W of the projected triangle then decide
 * the hit. A shared vertex is transformed identically for every triangle that uses it and
 * U(edge ab) = -U(edge ba) exactly (no fused multiply-add), so rays through a shared edge or vertex
 * hit at least one of the triangles that share it: no ray passes through a closed mesh. Edge
 * functions that round to exactly 0 are recomputed in double where the device has cl_khr_fp64
 * (the products of two floats are exact in double, so their sign is then right). With
 * --precision double (LC_DOUBLE) the whole test runs in double, without that fallback. */
#ifndef LUCENT_GEOM_TRIANGLE_CL
#define LUCENT_GEOM_TRIANGLE_CL

#if defined(cl_khr_fp64) && !defined(LC_DOUBLE)
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#define LC_TRI_FP64_FALLBACK 1
#endif

/* Per-ray constants of the watertight test. */
typedef struct {
  int kx, ky, kz;     /* kz: the dominant axis of d; kx, ky: the next two, cyclically */
  lc_real sx, sy, sz; /* shear: d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz] */
} lc_tri_ray;

static inline lc_real lc_get(lc_real3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

/* (v[a], v[b], v[c], 0): one permutation, where three chains of comparisons on a, b, c would be
 * branches that a diffuse ray's random direction mispredicts */
#ifdef LC_DOUBLE
#define lc_tri_lanes(v, a, b, c) \
  shuffle((double4)((v), 0.0), convert_ulong4((int4)((a), (b), (c), 3)))
#else
#define lc_tri_lanes(v, a, b, c) shuffle((float4)((v), 0.0f), as_uint4((int4)((a), (b), (c), 3)))
#endif

/* Woop et al. swap kx and ky when d[kz] < 0, to keep the triangles' winding for back-face
 * culling. The test here is two-sided, and without the swap U, V, W, det and T only change sign,
 * exactly (a - b is -(b - a) in IEEE arithmetic, and so are the sums and products built from
 * them): t = T / det and the barycentrics V / det, W / det are the same bits, and so is every
 * decision. Leaving it out saves a select on the direction's sign, which a diffuse ray's random
 * direction mispredicted as a branch: renders 1.04x (BENCHMARKS.md, "Mispredicted branches"). */
static inline lc_tri_ray triangle_ray_setup(lc_real3 d) {
  lc_tri_ray r;
  lc_real3 ad = fabs(d);
  int kz = (ad.x > ad.y) ? ((ad.x > ad.z) ? 0 : 2) : ((ad.y > ad.z) ? 1 : 2);
  int kx = kz == 2 ? 0 : kz + 1;
  int ky = kx == 2 ? 0 : kx + 1;
  lc_real4 p = lc_tri_lanes(d, kx, ky, kz);
  r.kz = kz;
  r.kx = kx;
  r.ky = ky;
  lc_real4 q = (lc_real4)(p.x, p.y, LC_REAL(1.0), LC_REAL(1.0)) / p.z;
  r.sx = q.x; /* d[kx] / d[kz] */
  r.sy = q.y; /* d[ky] / d[kz] */
  r.sz = q.z; /* 1 / d[kz] */
  return r;
}

/* On a hit with t in (tmin, tmax) returns 1 and writes t and the barycentrics (b1, b2) of v1, v2.
 * Both faces are hit; a degenerate triangle (zero area seen along the ray) is never hit. */
static inline int triangle_intersect(const lc_tri_ray* r, lc_real3 o, lc_real3 v0, lc_real3 v1,
                                     lc_real3 v2, lc_real tmin, lc_real tmax, lc_real* t_out,
                                     lc_real* b1_out, lc_real* b2_out) {
#pragma OPENCL FP_CONTRACT OFF
  lc_real3 A = v0 - o, B = v1 - o, C = v2 - o;
  lc_real Az = lc_get(A, r->kz), Bz = lc_get(B, r->kz), Cz = lc_get(C, r->kz);
  lc_real Ax = lc_get(A, r->kx) - r->sx * Az;
  lc_real Ay = lc_get(A, r->ky) - r->sy * Az;
  lc_real Bx = lc_get(B, r->kx) - r->sx * Bz;
  lc_real By = lc_get(B, r->ky) - r->sy * Bz;
  lc_real Cx = lc_get(C, r->kx) - r->sx * Cz;
  lc_real Cy = lc_get(C, r->ky) - r->sy * Cz;
  lc_real U = Cx * By - Cy * Bx;
  lc_real V = Ax * Cy - Ay * Cx;
  lc_real W = Bx * Ay - By * Ax;
#ifdef LC_TRI_FP64_FALLBACK
  if (U == 0.0f || V == 0.0f || W == 0.0f) {
    U = (float)((double)Cx * (double)By - (double)Cy * (double)Bx);
    V = (float)((double)Ax * (double)Cy - (double)Ay * (double)Cx);
    W = (float)((double)Bx * (double)Ay - (double)By * (double)Ax);
  }
#endif
  if ((U < LC_REAL(0.0) || V < LC_REAL(0.0) || W < LC_REAL(0.0)) &&
      (U > LC_REAL(0.0) || V > LC_REAL(0.0) || W > LC_REAL(0.0)))
    return 0;
  lc_real det = U + V + W;
  if (det == LC_REAL(0.0)) return 0;
  lc_real T = U * (r->sz * Az) + V * (r->sz * Bz) + W * (r->sz * Cz);
  lc_real inv = LC_REAL(1.0) / det;
  lc_real t = T * inv;
  if (!(t > tmin && t < tmax)) return 0;
  *t_out = t;
  *b1_out = V * inv;
  *b2_out = W * inv;
  return 1;
}

/* The bound on the absolute error of the point b0 v0 + b1 v1 + b2 v2, per component: gamma(7) of
 * the barycentric interpolation (pbrt-v4, section 6.8), lc_real's gamma. Shared by hits
 * (triangle_interaction) and emitted points (light/triangle.cl). */
static inline lc_real3 triangle_point_error(lc_real b0, lc_real b1, lc_real b2, lc_real3 v0,
                                            lc_real3 v1, lc_real3 v2) {
  return (fabs(b0 * v0) + fabs(b1 * v1) + fabs(b2 * v2)) *
         (LC_REAL(7.0) * LC_REAL_U * LC_REAL(1.0001));
}

/* The unit geometric normal, normalize((v1 - v0) x (v2 - v0)): lc_triangle.ng_x, ng_y, ng_z,
 * computed on the host in double and rounded once (the cross product and normalize in float took
 * ~100 instructions per hit and per light sample); under LC_DOUBLE computed here in double, but
 * the host's for a triangle that the rounding of its vertices to float made collinear (an
 * emitter still: a zero normal made every light sample on it dark). */
static inline lc_real3 triangle_normal(__global const lc_triangle* tri, lc_real3 v0, lc_real3 v1,
                                       lc_real3 v2) {
#ifdef LC_DOUBLE
  lc_real3 n = cross(v1 - v0, v2 - v0);
  lc_real len = length(n);
  return len > LC_REAL(0.0) ? n / len : (lc_real3)(tri->ng_x, tri->ng_y, tri->ng_z);
#else
  return (lc_real3)(tri->ng_x, tri->ng_y, tri->ng_z);
#endif
}

/* The surface at a hit on a triangle: barycentric position, interpolated normals and uvs where
 * the triangle has them (LC_HAS_SMOOTH_NORMALS, LC_HAS_UVS). */
static inline void triangle_interaction(const lc_scene* s, lc_ray ray, const lc_hit* hit,
                                        lc_interaction* it) {
  __global const lc_triangle* tri = &s->triangles[hit->prim];
  lc_real3 v0 = lc_load3ra(tri->v0), v1 = lc_load3ra(tri->v1), v2 = lc_load3ra(tri->v2);
  lc_real b1 = hit->b1, b2 = hit->b2, b0 = LC_REAL(1.0) - b1 - b2;
  it->p = b0 * v0 + b1 * v1 + b2 * v2;
  it->perr = triangle_point_error(b0, b1, b2, v0, v1, v2);
  lc_real3 ng = triangle_normal(tri, v0, v1, v2);
  it->ng = ng;
  float3 ngf = lc_float3_from_real3(ng);
  it->ns = ngf;
  float fb0 = (float)b0, fb1 = (float)b1, fb2 = (float)b2;
  it->uv = (float2)(fb1, fb2);
#if defined(LC_HAS_SMOOTH_NORMALS) || defined(LC_HAS_UVS)
  if (tri->flags & (LC_TRI_HAS_NORMALS | LC_TRI_HAS_UVS)) {
    __global const lc_triangle_attr* a = &s->tri_attrs[hit->prim];
#ifdef LC_HAS_SMOOTH_NORMALS
    if (tri->flags & LC_TRI_HAS_NORMALS) {
      float3 ns = fb0 * lc_load3(a->n) + fb1 * lc_load3(a->n + 3) + fb2 * lc_load3(a->n + 6);
      float len = length(ns);
      if (len > 0.0f) {
        ns /= len;
        /* interpolated normals stay on the geometric side */
        it->ns = dot(ns, ngf) < 0.0f ? -ns : ns;
      }
    }
#endif
#ifdef LC_HAS_UVS
    if (tri->flags & LC_TRI_HAS_UVS)
      it->uv = (float2)(fb0 * a->uv[0] + fb1 * a->uv[2] + fb2 * a->uv[4],
                        fb0 * a->uv[1] + fb1 * a->uv[3] + fb2 * a->uv[5]);
#endif
  }
#endif
  it->material = tri->material;
  it->light = tri->light;
}

#endif
