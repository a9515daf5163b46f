/* lucent kernel: caustics by light tracing (integrator.caustics; docs/rendering-model.md,
 * "Caustics by light tracing"). Each camera sample also traces one light path: from a light,
 * through a delta scattering first, then through any scatterings; each non-delta vertex after the
 * first is connected to the camera (the pinhole, or a point of a thin lens) and splatted with the
 * pixel filter's density into the film's light sums (atomically: any work-item may reach any
 * pixel). The path integrator leaves out the same paths, E N (N|S)* S L: a non-delta lobe at the
 * first hit, a delta one into the light (integrator/path.cl), so the two split path space. The
 * host divides the light sums by the number of light paths, W * H * spp. */
#ifndef LUCENT_INTEGRATOR_CAUSTICS_CL
#define LUCENT_INTEGRATOR_CAUSTICS_CL

/* The light sums: in double where the host defines LC_LIGHT_DOUBLE (devices with fp64 and
 * cl_khr_int64_base_atomics, src/render/features.cpp), added by a 64-bit compare-and-swap; a
 * pass's sum of squares cannot then overflow. In float otherwise. */
#ifdef LC_LIGHT_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
typedef double lc_lsum;
typedef double3 lc_lsum3;
typedef double4 lc_lsum4;
#define lc_lsum3_from(v) convert_double3(v)
#define lc_atomic_add_lsum lc_atomic_add_double
#else
typedef float lc_lsum;
typedef float3 lc_lsum3;
typedef float4 lc_lsum4;
#define lc_lsum3_from(v) (v)
#define lc_atomic_add_lsum lc_atomic_add_float
#endif

#ifdef LC_LIGHT_DOUBLE
/* *p += v for a double in global memory */
static inline void lc_atomic_add_double(volatile __global double* p, double v) {
  union {
    ulong u;
    double f;
  } old, sum;
  do {
    old.f = *p;
    sum.f = old.f + v;
  } while (atom_cmpxchg((volatile __global ulong*)p, old.u, sum.u) != old.u);
}
#else
/* *p += v for a float in global memory (OpenCL 1.2 has integer atomics only) */
static inline void lc_atomic_add_float(volatile __global float* p, float v) {
  union {
    unsigned int u;
    float f;
  } old, sum;
  do {
    old.f = *p;
    sum.f = old.f + v;
  } while (atomic_cmpxchg((volatile __global unsigned int*)p, old.u, sum.u) != old.u);
}
#endif

/* The light path's last connections (LC_CAUSTICS_HISTORY of them at most, in a ring): their film
 * positions and contributions c, for the cross terms of the sums of squares. A light path's value
 * at a pixel is the sum X = sum_k x_k of its connections' shares there (a path connects at every
 * non-delta vertex from y_2 on, and a wide filter or a small film puts several of them in one
 * pixel); the variance needs X^2, so share k adds x_k^2 + 2 x_k sum_{j<k} x_j, with the earlier
 * shares x_j recomputed from their film positions by the same filter density. A connection more
 * than LC_CAUSTICS_HISTORY connections back is forgotten: its cross terms are missing (the
 * variance of a path with more connections than that is slightly low; docs/rendering-model.md). */
#ifndef LC_CAUSTICS_HISTORY
#define LC_CAUSTICS_HISTORY 16
#endif
#if LC_CAUSTICS_HISTORY < 1 || LC_CAUSTICS_HISTORY > 32
#error "LC_CAUSTICS_HISTORY: 1 to 32 (a bit mask of them in caustics_splat)"
#endif
typedef struct {
  float fx[LC_CAUSTICS_HISTORY], fy[LC_CAUSTICS_HISTORY];
  float3 c[LC_CAUSTICS_HISTORY];
  lc_uint n; /* connections splatted so far; the last min(n, LC_CAUSTICS_HISTORY) are kept */
  /* the path's total: every share added to the light sums, over all pixels (its contribution to
   * the film's sum, the image mean's light part; megakernel.cl) */
  lc_lsum3 total;
} lc_caustics_history;

/* The earlier connections whose filter may share a pixel with one at (fx, fy) (each within 2 r
 * of it on both axes), as a bit mask: usually none, and then the splat needs no cross terms. */
static inline lc_uint caustics_history_near(const lc_caustics_history* h, float r, float fx,
                                            float fy) {
  lc_uint near = 0;
  const lc_uint n = min(h->n, (lc_uint)LC_CAUSTICS_HISTORY);
  for (lc_uint j = 0; j < n; ++j)
    if (fabs(h->fx[j] - fx) <= 2.0f * r && fabs(h->fy[j] - fy) <= 2.0f * r) near |= 1u << j;
  return near;
}

/* The sum of the earlier connections' shares (those in `near`) at the pixel of centre (cx, cy):
 * those that caustics_splat kept (a share whose square is not a finite float was dropped; where
 * the sums are floats, also one that the sum of squares could not take then, which is not
 * recomputed). */
static inline float3 caustics_history_at(const lc_caustics_history* h, lc_uint near, lc_uint filter,
                                         float r, float cx, float cy) {
  float3 sum = (float3)(0.0f);
  for (lc_uint j = 0; j < (lc_uint)LC_CAUSTICS_HISTORY; ++j) {
    const lc_uint rest = near >> j; /* j < 32: a defined shift */
    if (!rest) break;
    if (!(rest & 1u)) continue;
    float dx = h->fx[j] - cx, dy = h->fy[j] - cy;
    if (fabs(dx) > r || fabs(dy) > r) continue; /* beyond every filter's support */
    float w = filter_density(filter, r, dx, dy);
    if (!(w > 0.0f)) continue;
    float3 v = h->c[j] * w;
    if (lc_isfinite3(v * v)) sum += v;
  }
  return sum;
}

/* Adds contribution c (before the filter) at film position (fx, fy) to every pixel whose filter
 * reaches it, and to the sums of squares the share's square plus twice its product with the
 * earlier connections' shares in the same pixel (history h; the connection is then added to it).
 * Returns the number of pixel shares dropped: a share (c times the filter's density there) whose
 * square overflows a float, as the reference judges each pixel's share, or, where the light sums
 * are floats (no LC_LIGHT_DOUBLE), that would take the pixel's float sum of squares past FLT_MAX (a
 * few splats of 1e19 on one pixel in one pass made its variance infinite). That second test reads
 * the sum before the atomic adds: work-items that race there may still pass it together,
 * near 3.4e38. In double a pass's sums keep every share the first test keeps, as the reference's
 * do. */
static inline lc_uint caustics_splat(const lc_scene* s, float fx, float fy, float3 c,
                                     __global lc_lsum4* light_sum, __global lc_lsum4* light_sumsq,
                                     lc_caustics_history* h) {
  __global const lc_params* P = s->params;
  const float r = P->filter_radius;
  const int W = (int)P->width, H = (int)P->height;
  /* caustics_connect has checked that (fx, fy) lies within r of the film (so the casts to int
   * below are in range); the pixels whose centre (x + 0.5) lies within r of fx: */
  int x0 = max(0, (int)ceil(fx - r - 0.5f)), x1 = min(W - 1, (int)floor(fx + r - 0.5f));
  int y0 = max(0, (int)ceil(fy - r - 0.5f)), y1 = min(H - 1, (int)floor(fy + r - 0.5f));
  lc_uint dropped = 0;
  const lc_uint near = caustics_history_near(h, r, fx, fy);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      float w = filter_density(P->filter, r, fx - ((float)x + 0.5f), fy - ((float)y + 0.5f));
      if (!(w > 0.0f)) continue;
      float3 v = c * w, v2 = v * v;
      volatile __global lc_lsum* a = (volatile __global lc_lsum*)&light_sum[y * W + x];
      volatile __global lc_lsum* b = (volatile __global lc_lsum*)&light_sumsq[y * W + x];
      if (!lc_isfinite3(v2)) {
        ++dropped;
        continue;
      }
      /* x_k^2 + 2 x_k sum_{j<k} x_j (a share's square of floats is exact in double) */
      lc_lsum3 lv = lc_lsum3_from(v), lv2 = lv * lv;
      if (near)
        lv2 += (lc_lsum)2 * lv *
               lc_lsum3_from(
                   caustics_history_at(h, near, P->filter, r, (float)x + 0.5f, (float)y + 0.5f));
#ifndef LC_LIGHT_DOUBLE
      if (!lc_isfinite3(lv2) || !lc_isfinite3((float3)(b[0], b[1], b[2]) + lv2)) {
        ++dropped;
        continue;
      }
#endif
      h->total += lv;
      lc_atomic_add_lsum(a + 0, lv.x);
      lc_atomic_add_lsum(a + 1, lv.y);
      lc_atomic_add_lsum(a + 2, lv.z);
      lc_atomic_add_lsum(b + 0, lv2.x);
      lc_atomic_add_lsum(b + 1, lv2.y);
      lc_atomic_add_lsum(b + 2, lv2.z);
    }
  const lc_uint k = h->n % (lc_uint)LC_CAUSTICS_HISTORY;
  h->fx[k] = fx;
  h->fy[k] = fy;
  h->c[k] = c;
  ++h->n;
  return dropped;
}

/* Connects the light path's vertex at surface `surf` (interaction_surface's, reached by ray with
 * weight beta; its BSDF b) to the camera: to the pinhole, or to the point (lu, lv) of a thin
 * lens. The BSDF there is seen as a camera ray hitting the point would see it (its normals facing
 * the camera, the geometric one where the interpolated one faces away; b's side), so that the
 * contribution is exactly the one the path integrator leaves out. The surface and the BSDF are the
 * light path's, re-oriented: not computed again (one copy less of each in the kernel). Returns the
 * number of non-finite contributions dropped: 1 when the contribution is not finite, else the
 * pixel shares caustics_splat dropped (they are counted, not splatted). */
static inline lc_uint caustics_connect(const lc_scene* s, lc_ray ray, const lc_interaction* surf,
                                       const lc_bsdf* b_light, float lu, float lv, float3 beta,
                                       __global lc_lsum4* light_sum, __global lc_lsum4* light_sumsq,
                                       lc_caustics_history* h, lc_uint* rays) {
  const lc_real3 x = surf->p;
  __global const lc_params* P = s->params;
  __global const lc_camera* cam = &P->camera;
  float fx, fy, cos_c;
  lc_real3 cpos; /* the pinhole, or the lens point */
  if (!camera_project_lens(cam, x, lu, lv, P->width, P->height, &fx, &fy, &cos_c, &cpos)) return 0u;
  const float r = P->filter_radius;
  if (!(fx > -r && fx < (float)P->width + r && fy > -r && fy < (float)P->height + r)) return 0u;
  lc_real3 toc = cpos - x;
  lc_real dist = length(toc);
  if (!(dist > LC_REAL(0.0))) return 0u;
  lc_real3 wc = toc / dist;
  /* the interaction of the camera ray through this point */
  lc_interaction it = *surf;
  interaction_orient(&it, -wc);
  lc_bsdf b = *b_light;
  b.front = it.front;
  lc_frame fr = frame_from(it.ns);
  float3 wo_l = frame_to_local(&fr, lc_float3_from_real3(wc));
  if (wo_l.z <= 0.0f) return 0u;
  lc_real3 wl = -ray.d; /* towards the arriving light */
  float3 wi_l = frame_to_local(&fr, lc_float3_from_real3(wl));
  lc_real side = dot(wl, it.ng);
  if (wi_l.z < 0.0f ? side >= LC_REAL(0.0) : side <= LC_REAL(0.0)) return 0u; /* as path.cl */
  float pdf;
  float3 f = bsdf_eval(&b, wo_l, wi_l, &pdf);
  if (!(lc_max3(f) > 0.0f)) return 0u;
  lc_real3 o = lc_spawn_origin(it.p, it.perr, it.ng); /* ng faces the camera */
  lc_real3 to = cpos - o;
  lc_real od = length(to);
  if (!(od > LC_REAL(0.0)) || !shadow_visible(s, o, to / od, od, LC_SHADOW_REL_MARGIN, rays))
    return 0u;
  /* |wl.ns| |wc.ng| / |wl.ng|, and the importance 1 / (s^2 cos^3) over r^2, for a pinhole and
   * for a thin lens alike (with r and cos from the lens point: the lens point's density
   * 1 / area cancels the importance's 1 / area) */
  float cos_x = fabs(wi_l.z) * (float)dot(wc, it.ng) / (float)fabs(side);
  float pitch = 2.0f * cam->tan_half_fov / (float)P->height;
  float3 c = beta * f * (cos_x / ((float)(dist * dist) * pitch * pitch * cos_c * cos_c * cos_c));
  if (!lc_isfinite3(c)) return 1u;
  return caustics_splat(s, fx, fy, c, light_sum, light_sumsq, h);
}

/* The light path of the camera sample rng (random numbers from LC_DIM_LIGHT_PATH). Returns the
 * number of non-finite contributions it dropped, and in *total the sum of the shares it added to
 * the light sums (all pixels). Out of line on PoCL's CPU device (LC_POCL_NOINLINE, util/math.cl).
 */
static LC_POCL_NOINLINE lc_uint caustics_light_path(const lc_scene* s, const lc_rng* rng,
                                                    __global lc_lsum4* light_sum,
                                                    __global lc_lsum4* light_sumsq, lc_lsum3* total,
                                                    lc_uint* rays) {
  __global const lc_params* P = s->params;
  *total = (lc_lsum3)(0.0f);
  if (P->max_depth < 3u) return 0; /* a caustic path has at least 3 segments */
  float8 u0 = lc_rand8(rng, LC_DIM_LIGHT_PATH);
  float4 ue = u0.lo, ud = u0.hi;
  lc_ray ray;
  float3 beta;
  if (!light_emit(s, ue.z, (float4)(ue.x, ue.y, ud.x, ud.y), &ray, &beta)) return 0;
  const float beta0 = lc_max3(beta);
  lc_uint nonfinite = 0;
  lc_caustics_history h;
  h.n = 0;
  h.total = (lc_lsum3)(0.0f);
  int caustic = 0; /* 1 once the lobe sampled at y_1 was a delta one */
  /* scattering vertices 1 .. max_depth - 1: the camera path's segment limit */
  for (lc_uint i = 1; i < P->max_depth; ++i) {
    lc_hit hit;
    ++*rays;
    if (!scene_intersect(s, ray, INFINITY, &hit)) break;
    lc_interaction surf = interaction_surface(s, ray, &hit);
    lc_interaction it = surf;
    interaction_orient(&it, ray.d);
    __global const lc_material* m = &s->materials[it.material];
    lc_bsdf b = bsdf_from_material(s, m, it.uv, it.front);
    lc_uint dim = LC_DIM_LIGHT_PATH + 8u * i;
    float8 uv = lc_rand8(rng, dim);
    float4 ua = uv.lo, ub = uv.hi;
    if (caustic && !(bsdf_lobes(&b) & LC_BSDF_DELTA))
      nonfinite +=
          caustics_connect(s, ray, &surf, &b, ua.x, ua.y, beta, light_sum, light_sumsq, &h, rays);
    /* a light path goes on after a delta lobe at y_1, through any lobes after it */
    lc_frame fr = frame_from(it.ns);
    float3 wo_l = frame_to_local(&fr, lc_float3_from_real3(-ray.d));
    if (wo_l.z <= 0.0f) break;
    lc_bsdf_sample bs;
    if (!bsdf_sample(&b, wo_l, ua.w, ub.x, ub.y, &bs)) break;
    if (!caustic && !bs.delta) break;
    caustic = 1;
    lc_real3 wi = frame_to_world_dir(&fr, bs.wi);
    int transmit = bs.wi.z < 0.0f;
    lc_real side = dot(wi, it.ng);
    if (transmit ? side >= LC_REAL(0.0) : side <= LC_REAL(0.0)) break;
    /* the adjoint weight: power, not radiance, crosses a refraction (no 1 / eta^2; lucent's
     * other BSDFs are symmetric), and the shading-normal correction
     * |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|) */
    float wo_ng = (float)dot(-ray.d, it.ng);
    float corr = wo_l.z * (float)fabs(side) / (wo_ng * fabs(bs.wi.z));
    beta *= bs.weight * (bs.eta * bs.eta * corr);
    if (!(lc_max3(beta) > 0.0f)) break;
    ray.o = lc_spawn_origin(it.p, it.perr, transmit ? -it.ng : it.ng);
    ray.d = wi;
    /* Russian roulette on the throughput relative to the emitted weight, once the path has
     * rr_depth segments (y_0 .. y_i: i of them), as path.cl and the reference's light tracer do
     * (this started one vertex earlier: the same expectation, a variance 8% apart) */
    float q = lc_max3(beta) / beta0;
    if (i >= P->rr_depth && q < 1.0f) {
      if (ub.z >= q) break;
      beta /= q;
    }
  }
  *total = h.total;
  return nonfinite;
}

#endif
