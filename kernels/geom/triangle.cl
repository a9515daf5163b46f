/* lucent kernel: watertight ray/triangle intersection (Woop, Benthin and Wald, "Watertight
 * Ray/Triangle Intersection", JCGT 2013). Rays through a shared edge or vertex hit at least one of
 * the triangles that share it. */
#ifndef LUCENT_GEOM_TRIANGLE_CL
#define LUCENT_GEOM_TRIANGLE_CL

/* Per-ray constants of the watertight test. */
typedef struct {
  int kx, ky, kz;
  float sx, sy, sz;
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
  if (lc_get(d, r.kz) < 0.0f) {
    int tmp = r.kx;
    r.kx = r.ky;
    r.ky = tmp;
  }
  float dz = lc_get(d, r.kz);
  r.sx = lc_get(d, r.kx) / dz;
  r.sy = lc_get(d, r.ky) / dz;
  r.sz = 1.0f / dz;
  return r;
}

/* On a hit in (tmin, tmax) returns 1 and writes t and the barycentrics (b1, b2) of v1, v2. */
static inline int triangle_intersect(const lc_tri_ray* r, float3 o, float3 v0, float3 v1,
                                     float3 v2, float tmin, float tmax, float* t_out, float* b1_out,
                                     float* b2_out) {
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
