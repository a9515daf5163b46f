/* lucent kernel: watertight ray/triangle intersection (Woop, Benthin and Wald, "Watertight
 * Ray/Triangle Intersection", JCGT 2(1), 2013). The ray is sheared and scaled so that it runs
 * along +z through the origin; the 2D edge functions U, V, W of the projected triangle then decide
 * the hit. A shared vertex is transformed identically for every triangle that uses it and
 * U(edge ab) = -U(edge ba) exactly (no fused multiply-add), so rays through a shared edge or vertex
 * hit at least one of the triangles that share it: no ray passes through a closed mesh. Edge
 * functions that round to exactly 0 are recomputed in double where the device has cl_khr_fp64
 * (the products of two floats are exact in double, so their sign is then right). */
#ifndef LUCENT_GEOM_TRIANGLE_CL
#define LUCENT_GEOM_TRIANGLE_CL

#if defined(cl_khr_fp64)
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#define LC_TRI_FP64_FALLBACK 1
#endif

/* Per-ray constants of the watertight test. */
typedef struct {
  int kx, ky, kz; /* kz: the dominant axis of d; kx, ky: the others, swapped when d[kz] < 0 */
  float sx, sy, sz; /* shear: d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz] */
} lc_tri_ray;

static inline float lc_get(float3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

static inline lc_tri_ray triangle_ray_setup(float3 d) {
  lc_tri_ray r;
  float3 ad = fabs(d);
  r.kz = (ad.x > ad.y) ? ((ad.x > ad.z) ? 0 : 2) : ((ad.y > ad.z) ? 1 : 2);
  r.kx = r.kz + 1;
  if (r.kx == 3) r.kx = 0;
  r.ky = r.kx + 1;
  if (r.ky == 3) r.ky = 0;
  float dz = lc_get(d, r.kz);
  if (dz < 0.0f) { /* keep the winding, so U, V, W keep their meaning */
    int tmp = r.kx;
    r.kx = r.ky;
    r.ky = tmp;
  }
  r.sx = lc_get(d, r.kx) / dz;
  r.sy = lc_get(d, r.ky) / dz;
  r.sz = 1.0f / dz;
  return r;
}

/* On a hit with t in (tmin, tmax) returns 1 and writes t and the barycentrics (b1, b2) of v1, v2.
 * Both faces are hit; a degenerate triangle (zero area seen along the ray) is never hit. */
static inline int triangle_intersect(const lc_tri_ray* r, float3 o, float3 v0, float3 v1,
                                     float3 v2, float tmin, float tmax, float* t_out, float* b1_out,
                                     float* b2_out) {
#pragma OPENCL FP_CONTRACT OFF
  float3 A = v0 - o, B = v1 - o, C = v2 - o;
  float Az = lc_get(A, r->kz), Bz = lc_get(B, r->kz), Cz = lc_get(C, r->kz);
  float Ax = lc_get(A, r->kx) - r->sx * Az;
  float Ay = lc_get(A, r->ky) - r->sy * Az;
  float Bx = lc_get(B, r->kx) - r->sx * Bz;
  float By = lc_get(B, r->ky) - r->sy * Bz;
  float Cx = lc_get(C, r->kx) - r->sx * Cz;
  float Cy = lc_get(C, r->ky) - r->sy * Cz;
  float U = Cx * By - Cy * Bx;
  float V = Ax * Cy - Ay * Cx;
  float W = Bx * Ay - By * Ax;
#ifdef LC_TRI_FP64_FALLBACK
  if (U == 0.0f || V == 0.0f || W == 0.0f) {
    U = (float)((double)Cx * (double)By - (double)Cy * (double)Bx);
    V = (float)((double)Ax * (double)Cy - (double)Ay * (double)Cx);
    W = (float)((double)Bx * (double)Ay - (double)By * (double)Ax);
  }
#endif
  if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return 0;
  float det = U + V + W;
  if (det == 0.0f) return 0;
  float T = U * (r->sz * Az) + V * (r->sz * Bz) + W * (r->sz * Cz);
  float inv = 1.0f / det;
  float t = T * inv;
  if (!(t > tmin && t < tmax)) return 0;
  *t_out = t;
  *b1_out = V * inv;
  *b2_out = W * inv;
  return 1;
}

#endif
