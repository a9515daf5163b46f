/* Prototypes for issue 11 (design exploration; not part of the renderer), run by
 * bench/prototypes/proto_main.cpp (lucent_proto); figures in BENCHMARKS.md, "Where the time goes".
 * kernels/ is on the include path: the prototypes call the renderer's own functions, those of
 * commit f227b8a (before issue 10's refactor; later kernels need the includes and the stages'
 * scene arguments ported).
 *
 * 1. Wavefront: the megakernel's path integrator (kernels/integrator/path.cl, integrator_path)
 *    split into stages over a structure-of-arrays path state (st: float rows S_*, su: uint rows
 *    U_*), one work-item per path, one launch per stage and bounce:
 *      wf_generate -> [wf_trace -> wf_shade -> wf_shadow] x max_depth -> wf_film
 *    wf_shade runs the statements of one loop iteration of integrator_path with the same
 *    functions and random-number dimensions (the shadow test deferred to wf_shadow), so the
 *    image equals the megakernel's to the last bits.
 * 2. The same stages for PoCL's work-item-loop vectoriser: wf_generate_vec and wf_shade_vec, for
 *    the prototype's scenes only (diffuse, triangle lights, no environment, flat normals),
 *    written with a struct of three floats and without run-time loops.
 * 3. Explicit packets: wf_shade_pk shades WF_PK paths per work-item in float8/float16 lanes
 *    (masks for branches, lane-by-lane gathers of scene data); pk_mega keeps WF_PK paths per
 *    work-item for the whole path loop (a packet megakernel).
 * 4. Packet traversal: packet_trace (wf_trace_packet, wf_shadow_packet) traces WF_PACKET rays per
 *    work-item through the 8-wide BVH, every child box against every ray, a child entered when
 *    any active ray enters it; wf_trace_single traces the same rays one per work-item.
 * 5. Micro-kernels (m_*): what PoCL 3.1's vectoriser accepts.
 * 2 to 4 compute the same samples with slightly different arithmetic (their own normalisation
 * and spawn offset), so their images equal the megakernel's in the mean, not bit for bit.
 */
/* The per-path stage functions (wf_generate_at, wf_trace_at, wf_shadow_at, wf_film_at,
 * wf_shade_pk_at) are out of line by default, so that perf attributes pk_mega's time to them;
 * pk_mega measured 1.50 Mpaths per CPU second with them out of line, 1.47 inlined (Cornell box,
 * ninth session). -D WF_STAGE="static inline" inlines them. */
#ifndef WF_STAGE
#define WF_STAGE __attribute__((noinline)) static
#endif
/* the order matters: each file uses the ones before it */
// clang-format off
#include "shared/types.h"
#include "shared/rng.h"
#include "util/math.cl"
#include "geom/sphere.cl"
#include "geom/triangle.cl"
#include "bvh/traverse.cl"
#include "geom/interaction.cl"
#include "film/texture.cl"
#include "film/filter.cl"
#include "camera/camera.cl"
#include "bsdf/fresnel.cl"
#include "bsdf/microfacet.cl"
#include "bsdf/bsdf.cl"
#include "light/light.cl"
#include "integrator/path.cl"
// clang-format on

/* float state components, each an array of n floats: st[C * n + path] */
enum {
  S_OX,
  S_OY,
  S_OZ,
  S_DX,
  S_DY,
  S_DZ, /* current ray */
  S_BR,
  S_BG,
  S_BB, /* throughput */
  S_LR,
  S_LG,
  S_LB, /* radiance */
  S_PREV_PDF,
  S_PPX,
  S_PPY,
  S_PPZ, /* MIS: previous bsdf pdf and where light sampling was */
  S_HT,
  S_HB1,
  S_HB2, /* closest hit */
  S_SOX,
  S_SOY,
  S_SOZ,
  S_SDX,
  S_SDY,
  S_SDZ,
  S_STMAX, /* shadow ray */
  S_CR,
  S_CG,
  S_CB, /* its contribution when unoccluded */
  S_COUNT
};
/* uint state: flags and the hit primitive */
enum { U_FLAGS, U_PRIM, U_COUNT };
#define F_ALIVE 1u
#define F_PREV_DELTA 2u
#define F_SHADOW 4u

#define LD(c) st[(c)*n + i]
#define ST(c, v) st[(c)*n + i] = (v)

WF_STAGE void wf_generate_at(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n,
                             uint sample, uint i) {
  if (i >= n) return;
  lc_rng rng = {i, sample, params->seed};
  uint width = params->width, height = params->height;
  uint px = i % width, py = i / width;
  float2 off = filter_sample(params->filter, params->filter_radius, lc_rand(&rng, LC_DIM_FILTER),
                             lc_rand(&rng, LC_DIM_FILTER + 1));
  lc_ray ray = camera_generate_ray(&params->camera, (float)px + 0.5f + off.x,
                                   (float)py + 0.5f + off.y, width, height,
                                   lc_rand(&rng, LC_DIM_LENS), lc_rand(&rng, LC_DIM_LENS + 1));
  ST(S_OX, ray.o.x);
  ST(S_OY, ray.o.y);
  ST(S_OZ, ray.o.z);
  ST(S_DX, ray.d.x);
  ST(S_DY, ray.d.y);
  ST(S_DZ, ray.d.z);
  ST(S_BR, 1.0f);
  ST(S_BG, 1.0f);
  ST(S_BB, 1.0f);
  ST(S_LR, 0.0f);
  ST(S_LG, 0.0f);
  ST(S_LB, 0.0f);
  ST(S_PREV_PDF, 0.0f);
  ST(S_PPX, ray.o.x);
  ST(S_PPY, ray.o.y);
  ST(S_PPZ, ray.o.z);
  su[U_FLAGS * n + i] = F_ALIVE | F_PREV_DELTA;
}
__kernel void wf_generate(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n,
                          uint sample) {
  wf_generate_at(params, nodes, leaves, triangles, tri_attrs, spheres, materials, lights, light_cdf,
                 textures, texels, st, su, n, sample, (uint)get_global_id(0));
}

WF_STAGE void wf_trace_at(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n,
                          uint i) {
  if (i >= n || !(su[U_FLAGS * n + i] & F_ALIVE)) return;
  lc_scene s = LC_SCENE_FROM_KERNEL_ARGS;
  lc_ray ray;
  ray.o = (float3)(LD(S_OX), LD(S_OY), LD(S_OZ));
  ray.d = (float3)(LD(S_DX), LD(S_DY), LD(S_DZ));
  lc_hit hit;
  scene_intersect(&s, ray, INFINITY, &hit);
  ST(S_HT, hit.t);
  ST(S_HB1, hit.b1);
  ST(S_HB2, hit.b2);
  su[U_PRIM * n + i] = hit.prim;
}
__kernel void wf_trace(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n) {
  wf_trace_at(params, nodes, leaves, triangles, tri_attrs, spheres, materials, lights, light_cdf,
              textures, texels, st, su, n, (uint)get_global_id(0));
}

WF_STAGE void wf_shadow_at(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n,
                           uint i) {
  if (i >= n) return;
  uint flags = su[U_FLAGS * n + i];
  if (!(flags & F_SHADOW)) return;
  lc_scene s = LC_SCENE_FROM_KERNEL_ARGS;
  lc_ray sr;
  sr.o = (float3)(LD(S_SOX), LD(S_SOY), LD(S_SOZ));
  sr.d = (float3)(LD(S_SDX), LD(S_SDY), LD(S_SDZ));
  if (!scene_occluded(&s, sr, LD(S_STMAX))) {
    ST(S_LR, LD(S_LR) + LD(S_CR));
    ST(S_LG, LD(S_LG) + LD(S_CG));
    ST(S_LB, LD(S_LB) + LD(S_CB));
  }
  su[U_FLAGS * n + i] = flags & ~F_SHADOW;
}
__kernel void wf_shadow(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n) {
  wf_shadow_at(params, nodes, leaves, triangles, tri_attrs, spheres, materials, lights, light_cdf,
               textures, texels, st, su, n, (uint)get_global_id(0));
}

/* One bounce of integrator_path after the closest hit: the statements between two
 * scene_intersect calls, with the shadow test deferred to wf_shadow. */
__kernel void wf_shade(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n,
                       uint depth, uint sample) {
  uint i = get_global_id(0);
  if (i >= n) return;
  uint flags = su[U_FLAGS * n + i];
  if (!(flags & F_ALIVE)) return;
  lc_scene s = LC_SCENE_FROM_KERNEL_ARGS;
  __global const lc_params* P = params;
  lc_rng rng = {i, sample, P->seed};
  const lc_rng* r = &rng;
  lc_ray ray;
  ray.o = (float3)(LD(S_OX), LD(S_OY), LD(S_OZ));
  ray.d = (float3)(LD(S_DX), LD(S_DY), LD(S_DZ));
  float3 beta = (float3)(LD(S_BR), LD(S_BG), LD(S_BB));
  float3 L = (float3)(LD(S_LR), LD(S_LG), LD(S_LB));
  float prev_pdf = LD(S_PREV_PDF);
  int prev_delta = (flags & F_PREV_DELTA) != 0;
  float3 prev_p = (float3)(LD(S_PPX), LD(S_PPY), LD(S_PPZ));
  lc_hit hit;
  hit.t = LD(S_HT);
  hit.b1 = LD(S_HB1);
  hit.b2 = LD(S_HB2);
  hit.prim = su[U_PRIM * n + i];
  const int no_mis = (P->flags & LC_FLAG_NO_MIS) != 0;
  uint alive = 0, shadow = 0;
  float3 contrib = (float3)(0.0f), so = (float3)(0.0f), sd = (float3)(0.0f);
  float stmax = 0.0f;
  do { /* one pass; `break` ends the path as in integrator_path */
    if (hit.prim == LC_INVALID) {
      float pdf_l;
      float3 Le = env_radiance(&s, ray.d, &pdf_l);
      L += beta * Le * (prev_delta ? 1.0f : (no_mis ? 0.0f : mis_power(prev_pdf, pdf_l)));
      break;
    }
    lc_interaction it = interaction_from_hit(&s, ray, &hit);
    __global const lc_material* m = &s.materials[it.material];
    if (it.front && it.light != LC_INVALID) {
      float3 Le = lc_load3(m->emission);
      float w = 1.0f;
      if (!prev_delta) {
        float pdf_l = light_pdf_area(&s, it.light, prev_p, hit.t, dot(-ray.d, it.ng));
        w = no_mis ? 0.0f : mis_power(prev_pdf, pdf_l);
      }
      L += beta * Le * w;
    }
    if (depth + 2 > P->max_depth) break;
    lc_uint dim = LC_DIM_BOUNCE + depth * LC_DIMS_PER_BOUNCE;
    lc_bsdf b = bsdf_from_material(&s, m, it.uv);
    lc_frame fr = frame_from(it.ns);
    float3 wo_l = frame_to_local(&fr, -ray.d);
    if (wo_l.z <= 0.0f) break;
    float3 o = lc_spawn_origin(it.p, it.perr, it.ng);
    if (!bsdf_is_delta(&b) && P->num_lights > 0) {
      lc_light_sample ls;
      if (light_sample(&s, o, lc_rand(r, dim + LC_DIM_LIGHT_SELECT),
                       lc_rand(r, dim + LC_DIM_LIGHT_UV), lc_rand(r, dim + LC_DIM_LIGHT_UV + 1),
                       &ls) &&
          ls.pdf > 0.0f && dot(ls.wi, it.ng) > 0.0f) {
        float3 wi_l = frame_to_local(&fr, ls.wi);
        float pdf_b;
        float3 f = bsdf_eval(&b, wo_l, wi_l, &pdf_b);
        if (lc_max3(f) > 0.0f) {
          float w = (ls.delta || no_mis) ? 1.0f : mis_power(ls.pdf, pdf_b);
          contrib = beta * f * ls.L * (wi_l.z * w / ls.pdf);
          so = o;
          sd = ls.wi;
          stmax = isinf(ls.dist) ? INFINITY
                                 : ls.dist * (1.0f - LC_SHADOW_REL_MARGIN) -
                                       8.0f * FLT_EPSILON * (lc_max3(fabs(o)) + ls.dist);
          shadow = 1;
        }
      }
    }
    lc_bsdf_sample bs;
    if (!bsdf_sample(&b, wo_l, it.front, lc_rand(r, dim + LC_DIM_BSDF_LOBE),
                     lc_rand(r, dim + LC_DIM_BSDF_UV), lc_rand(r, dim + LC_DIM_BSDF_UV + 1), &bs))
      break;
    float3 wi = normalize(frame_to_world(&fr, bs.wi));
    int transmit = bs.wi.z < 0.0f;
    float side = dot(wi, it.ng);
    if (transmit ? side >= 0.0f : side <= 0.0f) break;
    beta *= bs.weight;
    if (!(lc_max3(beta) > 0.0f)) break;
    prev_delta = bs.delta;
    prev_pdf = bs.pdf;
    ray.o = transmit ? lc_spawn_origin(it.p, it.perr, -it.ng) : o;
    prev_p = ray.o;
    ray.d = wi;
    float q = lc_max3(beta);
    if (depth + 2 > P->rr_depth && q < 1.0f) {
      if (lc_rand(r, dim + LC_DIM_RR) >= q) break;
      beta /= q;
    }
    alive = 1;
  } while (0);
  ST(S_LR, L.x);
  ST(S_LG, L.y);
  ST(S_LB, L.z);
  ST(S_BR, beta.x);
  ST(S_BG, beta.y);
  ST(S_BB, beta.z);
  ST(S_OX, ray.o.x);
  ST(S_OY, ray.o.y);
  ST(S_OZ, ray.o.z);
  ST(S_DX, ray.d.x);
  ST(S_DY, ray.d.y);
  ST(S_DZ, ray.d.z);
  ST(S_PREV_PDF, prev_pdf);
  ST(S_PPX, prev_p.x);
  ST(S_PPY, prev_p.y);
  ST(S_PPZ, prev_p.z);
  ST(S_SOX, so.x);
  ST(S_SOY, so.y);
  ST(S_SOZ, so.z);
  ST(S_SDX, sd.x);
  ST(S_SDY, sd.y);
  ST(S_SDZ, sd.z);
  ST(S_STMAX, stmax);
  ST(S_CR, contrib.x);
  ST(S_CG, contrib.y);
  ST(S_CB, contrib.z);
  su[U_FLAGS * n + i] =
      (alive ? F_ALIVE : 0u) | (prev_delta ? F_PREV_DELTA : 0u) | (shadow ? F_SHADOW : 0u);
}

/* Per-pixel sums of the finished samples (one path per pixel per wave). */
WF_STAGE void wf_film_at(__global const float* st, uint n, __global float4* sum,
                         __global float4* sumsq, uint i) {
  if (i >= n) return;
  float3 L = (float3)(LD(S_LR), LD(S_LG), LD(S_LB));
  if (lc_isfinite3(L)) {
    sum[i] += (float4)(L, 1.0f);
    sumsq[i] += (float4)(L * L, 0.0f);
  }
}
__kernel void wf_film(__global const float* st, uint n, __global float4* sum,
                      __global float4* sumsq) {
  wf_film_at(st, n, sum, sumsq, (uint)get_global_id(0));
}

/* Straight-line micro-stages to see what PoCL's work-item loop vectoriser does with each:
 * wf_rng: WF_RNG_DIMS random numbers per path (the pcg4d hash); wf_camera: filter + camera ray. */
__kernel void wf_rng(__global float* st, uint n, uint sample, uint seed) {
  uint i = get_global_id(0);
  if (i >= n) return;
  float acc = 0.0f;
  for (uint d = 0; d < 16; ++d) acc += lc_rng_uniform(i, sample, d, seed);
  st[i] = acc;
}

/* ---- packet traversal: WF_PACKET rays per work-item ---- */
#ifndef WF_PACKET
#define WF_PACKET 16
#endif
#if WF_PACKET == 16
typedef float16 pf;
typedef int16 pi;
#define pvload vload16
#define pvstore vstore16
#define PCONVI convert_int16
#elif WF_PACKET == 8
typedef float8 pf;
typedef int8 pi;
#define pvload vload8
#define pvstore vstore8
#define PCONVI convert_int8
#endif

/* the shear of the watertight test, per lane (kz: dominant axis; kx, ky: the others, swapped
 * when d[kz] < 0), as lane selects */
static inline pf psel3(pi k, pf x, pf y, pf z) { return select(select(z, y, k == 1), x, k == 0); }

/* Traversal of WF_PACKET rays at once: closest hit with t < tmax per lane, or (any_hit) whether
 * anything lies closer than tmax (a lane stops at its first hit). Triangles only (spheres are
 * not handled: the prototype's scenes are meshes). Child order: by the smallest entry distance
 * over the active rays; entries carry that distance and are dropped once every active ray has a
 * closer hit. */
static inline void packet_trace(__global const lc_params* params, __global const lc_bvh_node* nodes,
                                __global const lc_bvh_leaf* leaves, pf ox, pf oy, pf oz, pf dx,
                                pf dy, pf dz, pi alive, pf tmax, int any_hit, pf* t_out,
                                pi* prim_out, pf* b1_out, pf* b2_out) {
  pf ix = 1.0f / dx, iy = 1.0f / dy, iz = 1.0f / dz;
  ix = select(ix, (pf)(INFINITY), isinf(ix));
  iy = select(iy, (pf)(INFINITY), isinf(iy));
  iz = select(iz, (pf)(INFINITY), isinf(iz));
  /* watertight shear per lane */
  pf adx = fabs(dx), ady = fabs(dy), adz = fabs(dz);
  pi kz = select(select((pi)2, (pi)1, ady > adz), select((pi)2, (pi)0, adx > adz), adx > ady);
  pi kx = select(kz + 1, (pi)0, kz == 2), ky = select(kx + 1, (pi)0, kx == 2);
  pf dkz = psel3(kz, dx, dy, dz);
  pi swap = dkz < 0.0f;
  pi tkx = select(kx, ky, swap), tky = select(ky, kx, swap);
  kx = tkx;
  ky = tky;
  pf sx = psel3(kx, dx, dy, dz) / dkz, sy = psel3(ky, dx, dy, dz) / dkz, sz = 1.0f / dkz;
  pf tbest = select((pf)(-INFINITY), tmax, alive); /* dead lanes never enter */
  pi prim = (pi)(-1);
  pi blocked = (pi)(0);
  pf hb1 = (pf)(0.0f), hb2 = (pf)(0.0f);
  uint stack_ref[LC_BVH_STACK_SIZE];
  float stack_t[LC_BVH_STACK_SIZE];
  int sp = 0;
  uint ref = 0;
  if (params->num_nodes == 0 || !any(alive)) ref = LC_INVALID;
  for (;;) {
    if (ref == LC_INVALID) {
      /* pop */
      float maxbest = -INFINITY;
      for (int k = 0; k < WF_PACKET; ++k) maxbest = fmax(maxbest, ((float*)&tbest)[k]);
      do {
        if (sp == 0) goto done;
        --sp;
      } while (!(stack_t[sp] < maxbest));
      ref = stack_ref[sp];
    }
    if (!(ref & LC_BVH_LEAF_BIT)) {
      __global const lc_bvh_node* nd = &nodes[ref];
      uint crefs[LC_BVH_WIDTH];
      float cdist[LC_BVH_WIDTH];
      int cnt = 0;
      for (int c = 0; c < LC_BVH_WIDTH; ++c) {
        uint cr = nd->child[c];
        if (cr == LC_INVALID) continue;
        pf t0x = (nd->bounds[0][c] - ox) * ix, t1x = (nd->bounds[1][c] - ox) * ix;
        pf t0y = (nd->bounds[2][c] - oy) * iy, t1y = (nd->bounds[3][c] - oy) * iy;
        pf t0z = (nd->bounds[4][c] - oz) * iz, t1z = (nd->bounds[5][c] - oz) * iz;
        pf tn = fmax(fmax(fmin(t0x, t1x), fmin(t0y, t1y)), fmax(fmin(t0z, t1z), 0.0f));
        pf tf = fmin(fmin(fmax(t0x, t1x), fmax(t0y, t1y)), fmin(fmax(t0z, t1z), tbest)) *
                LC_BVH_EXIT_WIDEN;
        pi hitc = tn <= tf;
        if (!any(hitc)) continue;
        pf tnm = select((pf)(INFINITY), tn, hitc);
        float dmin = INFINITY;
        for (int k = 0; k < WF_PACKET; ++k) dmin = fmin(dmin, ((float*)&tnm)[k]);
        /* insertion: cdist descending, so the last is the nearest */
        int j = cnt++;
        while (j > 0 && cdist[j - 1] < dmin) {
          cdist[j] = cdist[j - 1];
          crefs[j] = crefs[j - 1];
          --j;
        }
        cdist[j] = dmin;
        crefs[j] = cr;
      }
      if (cnt == 0) {
        ref = LC_INVALID;
        continue;
      }
      for (int k = 0; k < cnt - 1; ++k) {
        stack_ref[sp] = crefs[k];
        stack_t[sp] = cdist[k];
        ++sp;
      }
      ref = crefs[cnt - 1];
      continue;
    }
    /* leaf blocks */
    __global const lc_bvh_leaf* lf = &leaves[ref & LC_BVH_LEAF_FIRST_MASK];
    __global const lc_bvh_leaf* end =
        lf + ((ref & ~LC_BVH_LEAF_BIT) >> LC_BVH_LEAF_COUNT_SHIFT) + 1;
    for (; lf < end; ++lf) {
      for (int k = 0; k < 4; ++k) {
#pragma OPENCL FP_CONTRACT OFF
        uint pr = lf->prim[k];
        if (pr == LC_INVALID || (pr & LC_PRIM_SPHERE_BIT)) continue;
        pf Ax = lf->v[0][k] - ox, Ay = lf->v[1][k] - oy, Az = lf->v[2][k] - oz;
        pf Bx = lf->v[3][k] - ox, By = lf->v[4][k] - oy, Bz = lf->v[5][k] - oz;
        pf Cx = lf->v[6][k] - ox, Cy = lf->v[7][k] - oy, Cz = lf->v[8][k] - oz;
        pf az = psel3(kz, Ax, Ay, Az), bz = psel3(kz, Bx, By, Bz), cz = psel3(kz, Cx, Cy, Cz);
        pf ax = psel3(kx, Ax, Ay, Az) - sx * az, ay = psel3(ky, Ax, Ay, Az) - sy * az;
        pf bx = psel3(kx, Bx, By, Bz) - sx * bz, by = psel3(ky, Bx, By, Bz) - sy * bz;
        pf cx = psel3(kx, Cx, Cy, Cz) - sx * cz, cy = psel3(ky, Cx, Cy, Cz) - sy * cz;
        pf U = cx * by - cy * bx, V = ax * cy - ay * cx, W = bx * ay - by * ax;
        pi ok = ~(((U < 0.0f) | (V < 0.0f) | (W < 0.0f)) & ((U > 0.0f) | (V > 0.0f) | (W > 0.0f)));
        pf det = U + V + W;
        ok &= det != 0.0f;
        pf T = U * (sz * az) + V * (sz * bz) + W * (sz * cz);
        pf inv = 1.0f / det;
        pf t = T * inv;
        ok &= (t > 0.0f) & (t < tbest);
        if (any_hit) {
          blocked |= ok;
          tbest = select(tbest, (pf)(-INFINITY), ok); /* a blocked lane is done */
          if (!any(tbest > 0.0f)) goto done;
        } else {
          tbest = select(tbest, t, ok);
          prim = select(prim, (pi)(int)pr, ok);
          hb1 = select(hb1, V * inv, ok);
          hb2 = select(hb2, W * inv, ok);
        }
      }
    }
    ref = LC_INVALID;
  }
done:
  *t_out = tbest;
  *prim_out = any_hit ? blocked : prim;
  *b1_out = hb1;
  *b2_out = hb2;
}

static inline void wf_trace_packet_at(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su,
                                      uint n, uint i0) {
  if (i0 >= n) return;
  pf ox = pvload(0, st + S_OX * n + i0), oy = pvload(0, st + S_OY * n + i0),
     oz = pvload(0, st + S_OZ * n + i0);
  pf dx = pvload(0, st + S_DX * n + i0), dy = pvload(0, st + S_DY * n + i0),
     dz = pvload(0, st + S_DZ * n + i0);
  pi alive = (pvload(0, (__global const int*)su + U_FLAGS * n + i0) & (int)F_ALIVE) != 0;
  pf t, hb1, hb2;
  pi prim;
  packet_trace(params, nodes, leaves, ox, oy, oz, dx, dy, dz, alive, (pf)(INFINITY), 0, &t, &prim,
               &hb1, &hb2);
  pvstore(select((pf)(INFINITY), t, alive), 0, st + S_HT * n + i0);
  pvstore(prim, 0, (__global int*)su + U_PRIM * n + i0);
  pvstore(hb1, 0, st + S_HB1 * n + i0);
  pvstore(hb2, 0, st + S_HB2 * n + i0);
}
__kernel void wf_trace_packet(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n) {
  wf_trace_packet_at(params, nodes, leaves, triangles, tri_attrs, spheres, materials, lights,
                     light_cdf, textures, texels, st, su, n, (uint)get_global_id(0) * WF_PACKET);
}

/* Shadow rays of WF_PACKET paths at once (any hit), adding the unoccluded contributions. */
static inline void wf_shadow_packet_at(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su,
                                       uint n, uint i0) {
  if (i0 >= n) return;
  pi flags = pvload(0, (__global const int*)su + U_FLAGS * n + i0);
  pi act = (flags & (int)F_SHADOW) != 0;
  if (!any(act)) return;
  pf ox = pvload(0, st + S_SOX * n + i0), oy = pvload(0, st + S_SOY * n + i0),
     oz = pvload(0, st + S_SOZ * n + i0);
  pf dx = pvload(0, st + S_SDX * n + i0), dy = pvload(0, st + S_SDY * n + i0),
     dz = pvload(0, st + S_SDZ * n + i0);
  pf t, hb1, hb2;
  pi blocked;
  packet_trace(params, nodes, leaves, ox, oy, oz, dx, dy, dz, act, pvload(0, st + S_STMAX * n + i0),
               1, &t, &blocked, &hb1, &hb2);
  pi add = act & ~blocked;
  pvstore(pvload(0, st + S_LR * n + i0) + select((pf)(0.0f), pvload(0, st + S_CR * n + i0), add), 0,
          st + S_LR * n + i0);
  pvstore(pvload(0, st + S_LG * n + i0) + select((pf)(0.0f), pvload(0, st + S_CG * n + i0), add), 0,
          st + S_LG * n + i0);
  pvstore(pvload(0, st + S_LB * n + i0) + select((pf)(0.0f), pvload(0, st + S_CB * n + i0), add), 0,
          st + S_LB * n + i0);
  pvstore(flags & ~(int)F_SHADOW, 0, (__global int*)su + U_FLAGS * n + i0);
}
__kernel void wf_shadow_packet(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su,
                               uint n) {
  wf_shadow_packet_at(params, nodes, leaves, triangles, tri_attrs, spheres, materials, lights,
                      light_cdf, textures, texels, st, su, n, (uint)get_global_id(0) * WF_PACKET);
}

/* The same rays one per work-item through the renderer's traversal, for comparison. */
__kernel void wf_trace_single(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n) {
  uint i = get_global_id(0);
  if (i >= n) return;
  lc_scene s = LC_SCENE_FROM_KERNEL_ARGS;
  if (!(su[U_FLAGS * n + i] & F_ALIVE)) {
    st[S_HT * n + i] = INFINITY;
    su[U_PRIM * n + i] = LC_INVALID;
    return;
  }
  lc_ray ray;
  ray.o = (float3)(LD(S_OX), LD(S_OY), LD(S_OZ));
  ray.d = (float3)(LD(S_DX), LD(S_DY), LD(S_DZ));
  lc_hit hit;
  scene_intersect(&s, ray, INFINITY, &hit);
  ST(S_HT, hit.prim == LC_INVALID ? INFINITY : hit.t);
  su[U_PRIM * n + i] = hit.prim;
}

/* ---- micro-kernels: what PoCL's work-item loop vectoriser accepts (mode "micro") ---- */
__kernel void m_axpy(__global float* x, uint n) {
  uint i = get_global_id(0);
  if (i >= n) return;
  x[i] = x[i] * 1.5f + 0.25f;
}
__kernel void m_axpy_nocheck(__global float* x, uint n) {
  uint i = get_global_id(0);
  x[i] = x[i] * 1.5f + 0.25f;
}
__kernel void m_sqrt(__global float* x, uint n) {
  uint i = get_global_id(0);
  x[i] = sqrt(x[i] + 1.0f);
}
__kernel void m_sinpi(__global float* x, uint n) {
  uint i = get_global_id(0);
  x[i] = sinpi(x[i]);
}
__kernel void m_isfinite(__global float* x, uint n) {
  uint i = get_global_id(0);
  x[i] = isfinite(x[i]) ? x[i] : 0.0f;
}
__kernel void m_select(__global float* x, uint n) {
  uint i = get_global_id(0);
  float v = x[i];
  x[i] = v > 0.5f ? v * v : v + 1.0f;
}
__kernel void m_rng(__global float* x, uint n) {
  uint i = get_global_id(0);
  float acc = 0.0f;
  for (uint d = 0; d < 16; ++d) acc += lc_rng_uniform(i, 7u, d, 0u);
  x[i] = acc;
}
__kernel void m_normalize3(__global float* x, uint n) {
  uint i = get_global_id(0);
  float3 v = (float3)(x[i], x[n + i], x[2 * n + i]);
  v = normalize(v + (float3)(1.0f));
  x[i] = v.x;
  x[n + i] = v.y;
  x[2 * n + i] = v.z;
}
__kernel void m_wf_film(__global float* x, uint n) {
  uint i = get_global_id(0);
  float3 L = (float3)(x[i], x[n + i], x[2 * n + i]);
  if (lc_isfinite3(L)) x[3 * n + i] += L.x + L.y + L.z;
}
__kernel void m_rng_int(__global float* x, uint n) {
  uint i = get_global_id(0);
  uint acc = 0;
  for (uint d = 0; d < 16; ++d) acc ^= lc_hash4(i, 7u, d, 0u);
  x[i] = (float)(acc >> 8);
}
__kernel void m_normalize3_inline(__global float* x, uint n) {
  uint i = get_global_id(0);
  float3 v = (float3)(x[i], x[n + i], x[2 * n + i]) + (float3)(1.0f);
  v = v * rsqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  x[i] = v.x;
  x[n + i] = v.y;
  x[2 * n + i] = v.z;
}
__kernel void m_dot3(__global float* x, uint n) {
  uint i = get_global_id(0);
  float3 v = (float3)(x[i], x[n + i], x[2 * n + i]);
  x[i] = dot(v, v);
}
__kernel void m_cosine_sample(__global float* x, uint n) {
  uint i = get_global_id(0);
  float3 w = sample_cosine_hemisphere(x[i], x[n + i]);
  x[i] = w.x;
  x[n + i] = w.y;
  x[2 * n + i] = w.z;
}
typedef struct {
  float x, y, z;
} m_v3;
static inline m_v3 m_v3_make(float x, float y, float z) {
  m_v3 r = {x, y, z};
  return r;
}
static inline float m_v3_dot(m_v3 a, m_v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline m_v3 m_v3_scale(m_v3 a, float s) { return m_v3_make(a.x * s, a.y * s, a.z * s); }
__kernel void m_normalize3_struct(__global float* x, uint n) {
  uint i = get_global_id(0);
  m_v3 v = m_v3_make(x[i] + 1.0f, x[n + i] + 1.0f, x[2 * n + i] + 1.0f);
  v = m_v3_scale(v, 1.0f / sqrt(m_v3_dot(v, v)));
  x[i] = v.x;
  x[n + i] = v.y;
  x[2 * n + i] = v.z;
}
__kernel void m_cosine_sample_struct(__global float* x, uint n) {
  uint i = get_global_id(0);
  float u1 = x[i], u2 = x[n + i];
  float r = sqrt(u1);
  float c = cospi(2.0f * u2), s = sinpi(2.0f * u2);
  x[i] = r * c;
  x[n + i] = r * s;
  x[2 * n + i] = sqrt(fmax(0.0f, 1.0f - u1));
}

/* ---- stages written for PoCL's work-item-loop vectoriser (_vec) ----
 * The same computations as wf_generate / wf_shade for the prototype's scenes (diffuse materials,
 * triangle lights, no environment, no textures, flat normals: the Cornell box and the dragon
 * box), written with a struct of three floats instead of float3 and without loops of run-time
 * length: PoCL 3.1's loop vectoriser (LLVM 15) rejects any vector-typed value ("instruction
 * return type cannot be vectorized") and any inner loop, so the renderer's float3 code runs one
 * work-item at a time. The light CDF search runs WF_CDF_ITERS fixed, branch-free steps
 * (ceil(log2(lights)), set by the host); the spawn offset's nextafter is an integer step.
 * Result: wf_generate_vec is vectorised (8 lanes), wf_shade_vec is not: the SLP vectoriser,
 * which runs when the program is built, packs the x and y components of its arithmetic into
 * <2 x float> operations, which the work-item loop vectoriser then rejects, and PoCL accepts no
 * build option to turn SLP off (-fno-slp-vectorize and -mllvm are "Invalid build option"). */
typedef struct {
  float x, y, z;
} v3;
/* Macros, not functions: clang's x86-64 calling convention passes and returns a struct of three
 * floats as {<2 x float>, float}, and those two-lane vectors survive inlining as phis and
 * insert/extract pairs, which is enough to stop PoCL's work-item loop vectoriser. */
#define V3T v3 /* the vector struct the macros build (pv3 in the packet stage) */
#define v3m(a, b, c) ((V3T){(a), (b), (c)})
#define v3_ld(p) v3m((p)[0], (p)[1], (p)[2])
/* A load of three floats whose adjacency the compiler cannot prove (wf_zero is 0 at run time), so
 * that SLP does not pack the x and y loads into one <2 x float> load (it still packs arithmetic:
 * see above). */
#define v3_ldg(p) v3m((p)[0], (p)[1 + wf_zero], (p)[2 + wf_zero])
#define v3_add(a, b) v3m((a).x + (b).x, (a).y + (b).y, (a).z + (b).z)
#define v3_sub(a, b) v3m((a).x - (b).x, (a).y - (b).y, (a).z - (b).z)
#define v3_mul(a, b) v3m((a).x*(b).x, (a).y*(b).y, (a).z*(b).z)
#define v3_s(a, s) v3m((a).x*(s), (a).y*(s), (a).z*(s))
#define v3_div(a, s) v3m((a).x / (s), (a).y / (s), (a).z / (s))
#define v3_neg(a) v3m(-(a).x, -(a).y, -(a).z)
#define v3_abs(a) v3m(fabs((a).x), fabs((a).y), fabs((a).z))
#define v3_dot(a, b) ((a).x * (b).x + (a).y * (b).y + (a).z * (b).z)
#define v3_max(a) fmax((a).x, fmax((a).y, (a).z))
#define v3_cross(a, b) \
  v3m((a).y*(b).z - (a).z * (b).y, (a).z * (b).x - (a).x * (b).z, (a).x * (b).y - (a).y * (b).x)
#define v3_norm(a) v3_s((a), 1.0f / sqrt(v3_dot((a), (a))))
#define v3_sel(a, b, c) ((c) ? (b) : (a))
static inline float v_nudge(float x, float nn) {
  int away = (x >= 0.0f) == (nn > 0.0f);
  float r = as_float(as_int(x) + (nn == 0.0f ? 0 : (away ? 1 : -1)));
  return x == 0.0f ? (nn > 0.0f ? as_float(1) : (nn < 0.0f ? as_float((int)0x80000001) : x)) : r;
}
#define V3_SPAWN(o, p, perr, nn)                                            \
  do {                                                                      \
    float d_ = v3_dot(v3_abs(nn), perr) + 2.0f * v3_max(perr);              \
    v3 t_ = v3_add(p, v3_s(nn, d_));                                        \
    o = v3m(v_nudge(t_.x, nn.x), v_nudge(t_.y, nn.y), v_nudge(t_.z, nn.z)); \
  } while (0)
#ifndef WF_CDF_ITERS
#define WF_CDF_ITERS 4
#endif
static inline uint v_cdf_search(__global const float* cdf, uint nl, float u) {
  uint lo = 0, hi = nl - 1;
  for (int k = 0; k < WF_CDF_ITERS; ++k) {
    uint mid = (lo + hi) >> 1;
    int act = lo < hi, c = cdf[mid] <= u;
    lo = (act && c) ? mid + 1 : lo;
    hi = (act && !c) ? mid : hi;
  }
  return lo;
}
#define VLD(c) st[(c)*n + i]

__kernel void wf_generate_vec(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n,
                              uint sample) {
  uint i = get_global_id(0);
  if (i >= n) return;
  uint seed = params->seed, width = params->width, height = params->height;
  float r = params->filter_radius;
  float fx = (float)(i % width) + 0.5f +
             (lc_rng_uniform(i, sample, LC_DIM_FILTER, seed) - 0.5f) * 2.0f * r;
  float fy = (float)(i / width) + 0.5f +
             (lc_rng_uniform(i, sample, LC_DIM_FILTER + 1, seed) - 0.5f) * 2.0f * r;
  __global const lc_camera* cam = &params->camera;
  float ndc_x = (2.0f * fx / (float)width - 1.0f) * cam->tan_half_fov * cam->aspect;
  float ndc_y = (1.0f - 2.0f * fy / (float)height) * cam->tan_half_fov;
  v3 dir = v3_norm(v3_add(v3_add(v3_ld(cam->forward), v3_s(v3_ld(cam->right), ndc_x)),
                          v3_s(v3_ld(cam->up), ndc_y)));
  v3 o = v3_ld(cam->position);
  ST(S_OX, o.x);
  ST(S_OY, o.y);
  ST(S_OZ, o.z);
  ST(S_DX, dir.x);
  ST(S_DY, dir.y);
  ST(S_DZ, dir.z);
  ST(S_BR, 1.0f);
  ST(S_BG, 1.0f);
  ST(S_BB, 1.0f);
  ST(S_LR, 0.0f);
  ST(S_LG, 0.0f);
  ST(S_LB, 0.0f);
  ST(S_PREV_PDF, 0.0f);
  ST(S_PPX, o.x);
  ST(S_PPY, o.y);
  ST(S_PPZ, o.z);
  su[U_FLAGS * n + i] = F_ALIVE | F_PREV_DELTA;
}

__kernel void wf_shade_vec(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n,
                           uint depth, uint sample) {
  uint i = get_global_id(0);
  if (i >= n) return;
  uint flags = su[U_FLAGS * n + i];
  if (!(flags & F_ALIVE)) return;
  __global const lc_params* P = params;
  uint seed = P->seed;
  const uint wf_zero = P->ao_distance < 0.0f; /* never: ao_distance is >= 0 (see v3_ldg) */
  v3 ro = v3m(VLD(S_OX), VLD(S_OY), VLD(S_OZ)), rd = v3m(VLD(S_DX), VLD(S_DY), VLD(S_DZ));
  v3 beta = v3m(VLD(S_BR), VLD(S_BG), VLD(S_BB)), L = v3m(VLD(S_LR), VLD(S_LG), VLD(S_LB));
  float prev_pdf = VLD(S_PREV_PDF);
  int prev_delta = (flags & F_PREV_DELTA) != 0;
  v3 prev_p = v3m(VLD(S_PPX), VLD(S_PPY), VLD(S_PPZ));
  float ht = VLD(S_HT), b1 = VLD(S_HB1), b2 = VLD(S_HB2);
  uint prim = su[U_PRIM * n + i];
  uint alive = 0, shadow = 0;
  v3 contrib = v3m(0.0f, 0.0f, 0.0f), so = contrib, sd = contrib;
  float stmax = 0.0f;
  if (prim != LC_INVALID) { /* a miss ends the path: the prototype's scenes have no environment */
    __global const lc_triangle* tri = &triangles[prim];
    v3 v0 = v3_ldg(tri->v0), v1 = v3_ldg(tri->v1), v2 = v3_ldg(tri->v2);
    float b0 = 1.0f - b1 - b2;
    v3 p = v3_add(v3_add(v3_s(v0, b0), v3_s(v1, b1)), v3_s(v2, b2));
    v3 perr = v3_s(v3_add(v3_add(v3_abs(v3_s(v0, b0)), v3_abs(v3_s(v1, b1))), v3_abs(v3_s(v2, b2))),
                   7.0f * LC_REAL_U * 1.0001f);
    v3 ng = v3_norm(v3_cross(v3_sub(v1, v0), v3_sub(v2, v0)));
    int front = v3_dot(rd, ng) < 0.0f;
    ng = v3_sel(v3_neg(ng), ng, front);
    uint mat = tri->material, light = tri->light;
    __global const lc_material* m = &materials[mat];
    if (front && light != LC_INVALID) {
      float w = 1.0f;
      if (!prev_delta) {
        __global const lc_light* Lt = &lights[light];
        float cos_l = -v3_dot(rd, ng);
        float pdf_l = cos_l > 0.0f ? Lt->pdf_select * ht * ht / (cos_l * Lt->area) : 0.0f;
        w = mis_power(prev_pdf, pdf_l);
      }
      L = v3_add(L, v3_s(v3_mul(beta, v3_ldg(m->emission)), w));
    }
    v3 ns = ng;
    float wo_z = -v3_dot(rd, ns);
    if (depth + 2 <= P->max_depth && wo_z > 0.0f) {
      uint dim = LC_DIM_BOUNCE + depth * LC_DIMS_PER_BOUNCE;
      v3 albedo = v3_ldg(m->albedo);
      float sgn = copysign(1.0f, ns.z), a = -1.0f / (sgn + ns.z), c = ns.x * ns.y * a;
      v3 ft = v3m(1.0f + sgn * ns.x * ns.x * a, sgn * c, -sgn * ns.x);
      v3 fb = v3m(c, sgn + ns.y * ns.y * a, -ns.y);
      v3 o;
      V3_SPAWN(o, p, perr, ng);
      /* next-event estimation: triangle lights */
      float us = lc_rng_uniform(i, sample, dim + LC_DIM_LIGHT_SELECT, seed);
      float u1 = lc_rng_uniform(i, sample, dim + LC_DIM_LIGHT_UV, seed);
      float u2 = lc_rng_uniform(i, sample, dim + LC_DIM_LIGHT_UV + 1, seed);
      uint li = v_cdf_search(light_cdf, P->num_lights, us);
      __global const lc_light* Ls = &lights[li];
      __global const lc_triangle* lt = &triangles[Ls->prim];
      v3 l0 = v3_ldg(lt->v0), l1 = v3_ldg(lt->v1), l2 = v3_ldg(lt->v2);
      float su_ = sqrt(u1), lb0 = 1.0f - su_, lb1 = u2 * su_;
      v3 q = v3_add(v3_add(v3_s(l0, lb0), v3_s(l1, lb1)), v3_s(l2, 1.0f - lb0 - lb1));
      v3 nl = v3_norm(v3_cross(v3_sub(l1, l0), v3_sub(l2, l0)));
      v3 to = v3_sub(q, o);
      float d2 = v3_dot(to, to), dist = sqrt(d2);
      v3 wi = v3_div(to, dist);
      float cos_l = -v3_dot(wi, nl);
      float pdf = Ls->pdf_select * d2 / (cos_l * Ls->area);
      float wi_z = v3_dot(wi, ns);
      if (dist > 0.0f && cos_l > 0.0f && pdf > 0.0f && v3_dot(wi, ng) > 0.0f && wi_z > 0.0f &&
          v3_max(albedo) > 0.0f) {
        float w = mis_power(pdf, wi_z * LC_INV_PI);
        contrib = v3_s(v3_mul(v3_mul(beta, v3_s(albedo, LC_INV_PI)), v3_ldg(Ls->intensity)),
                       wi_z * w / pdf);
        so = o;
        sd = wi;
        stmax =
            dist * (1.0f - LC_SHADOW_REL_MARGIN) - 8.0f * FLT_EPSILON * (v3_max(v3_abs(o)) + dist);
        shadow = 1;
      }
      /* cosine-weighted BSDF sample */
      float ub1 = lc_rng_uniform(i, sample, dim + LC_DIM_BSDF_UV, seed);
      float ub2 = lc_rng_uniform(i, sample, dim + LC_DIM_BSDF_UV + 1, seed);
      float r = sqrt(ub1), x2 = 2.0f * ub2;
      float lx = r * cospi(x2), ly = r * sinpi(x2), lz = sqrt(fmax(0.0f, 1.0f - ub1));
      float bpdf = lz * LC_INV_PI;
      v3 nwi = v3_norm(v3_add(v3_add(v3_s(ft, lx), v3_s(fb, ly)), v3_s(ns, lz)));
      v3 nbeta = v3_mul(beta, albedo);
      if (bpdf > 0.0f && v3_dot(nwi, ng) > 0.0f && v3_max(nbeta) > 0.0f) {
        float qq = v3_max(nbeta);
        int rr = depth + 2 > P->rr_depth && qq < 1.0f;
        float urr = lc_rng_uniform(i, sample, dim + LC_DIM_RR, seed);
        if (!(rr && urr >= qq)) {
          beta = rr ? v3_div(nbeta, qq) : nbeta;
          prev_delta = 0;
          prev_pdf = bpdf;
          ro = o;
          prev_p = o;
          rd = nwi;
          alive = 1;
        }
      }
    }
  }
  ST(S_LR, L.x);
  ST(S_LG, L.y);
  ST(S_LB, L.z);
  ST(S_BR, beta.x);
  ST(S_BG, beta.y);
  ST(S_BB, beta.z);
  ST(S_OX, ro.x);
  ST(S_OY, ro.y);
  ST(S_OZ, ro.z);
  ST(S_DX, rd.x);
  ST(S_DY, rd.y);
  ST(S_DZ, rd.z);
  ST(S_PREV_PDF, prev_pdf);
  ST(S_PPX, prev_p.x);
  ST(S_PPY, prev_p.y);
  ST(S_PPZ, prev_p.z);
  ST(S_SOX, so.x);
  ST(S_SOY, so.y);
  ST(S_SOZ, so.z);
  ST(S_SDX, sd.x);
  ST(S_SDY, sd.y);
  ST(S_SDZ, sd.z);
  ST(S_STMAX, stmax);
  ST(S_CR, contrib.x);
  ST(S_CG, contrib.y);
  ST(S_CB, contrib.z);
  su[U_FLAGS * n + i] =
      (alive ? F_ALIVE : 0u) | (prev_delta ? F_PREV_DELTA : 0u) | (shadow ? F_SHADOW : 0u);
}

/* ---- the same stage as explicit packets: WF_PK paths per work-item in floatN lanes ----
 * No vectoriser involved: every value is a float8 (or float16), branches become lane masks,
 * loads of per-path scene data (triangles, materials, lights, the light CDF) are lane-by-lane
 * gathers. The v3 macros above work on it unchanged (V3T = pv3). */
#ifndef WF_PK
#define WF_PK 8
#endif
#if WF_PK == 8
typedef float8 kf;
typedef int8 ki;
typedef uint8 ku;
#define kload vload8
#define kstore vstore8
#define k_as_u as_uint8
#define k_as_i as_int8
#define k_u2f convert_float8
#define k_as_f as_float8
#define K_IOTA ((ku)(0, 1, 2, 3, 4, 5, 6, 7))
#elif WF_PK == 16
typedef float16 kf;
typedef int16 ki;
typedef uint16 ku;
#define kload vload16
#define kstore vstore16
#define k_as_u as_uint16
#define k_as_i as_int16
#define k_u2f convert_float16
#define k_as_f as_float16
#define K_IOTA ((ku)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15))
#endif
typedef struct {
  kf x, y, z;
} pv3;
#define pv3_sel(a, b, m) \
  ((pv3){select((a).x, (b).x, (m)), select((a).y, (b).y, (m)), select((a).z, (b).z, (m))})
#define KL(v, k) (((__private float*)&(v))[k])
#define KLU(v, k) (((__private uint*)&(v))[k])
/* lane-by-lane gather of three consecutive floats at base[idx[k]] + off (lanes with m[k] == 0
 * read index 0) */
#define PK_GATHER3(dst, T, arr, idxv, m, field)                                       \
  do {                                                                                \
    float gx_[WF_PK], gy_[WF_PK], gz_[WF_PK];                                         \
    for (int k_ = 0; k_ < WF_PK; ++k_) {                                              \
      __global const T* e_ = &(arr)[((__private int*)&(m))[k_] ? KLU(idxv, k_) : 0u]; \
      gx_[k_] = e_->field[0];                                                         \
      gy_[k_] = e_->field[1];                                                         \
      gz_[k_] = e_->field[2];                                                         \
    }                                                                                 \
    dst = (pv3){kload(0, gx_), kload(0, gy_), kload(0, gz_)};                         \
  } while (0)
#define PK_GATHER1(dst, T, arr, idxv, m, field, type, vt)                    \
  do {                                                                       \
    type g_[WF_PK];                                                          \
    for (int k_ = 0; k_ < WF_PK; ++k_)                                       \
      g_[k_] = (arr)[((__private int*)&(m))[k_] ? KLU(idxv, k_) : 0u].field; \
    dst = (vt)kload(0, g_);                                                  \
  } while (0)

/* pcg4d (shared/rng.h) on lanes */
static inline kf pk_rand(ku x, ku y, ku z, ku w) {
  x = x * 1664525u + 1013904223u;
  y = y * 1664525u + 1013904223u;
  z = z * 1664525u + 1013904223u;
  w = w * 1664525u + 1013904223u;
  x += y * w;
  y += z * x;
  z += x * y;
  w += y * z;
  x ^= x >> 16u;
  y ^= y >> 16u;
  z ^= z >> 16u;
  w ^= w >> 16u;
  x += y * w;
  y += z * x;
  z += x * y;
  w += y * z;
  return k_u2f((x ^ w) >> 8u) * (1.0f / 16777216.0f);
}
static inline kf pk_mis(kf a, kf b) {
  kf a2 = a * a, b2 = b * b, s = a2 + b2;
  return select(select((kf)(0.0f), a2 / s, s > 0.0f), (kf)(1.0f), isinf(a));
}
static inline kf pk_nudge(kf x, kf nn) {
  ki away = (x >= 0.0f) == (nn > 0.0f);
  ki step = select(select((ki)(-1), (ki)(1), away), (ki)(0), nn == 0.0f);
  kf r = k_as_f(k_as_i(x) + step);
  kf z = select(select(x, k_as_f((ki)(int)0x80000001), nn < 0.0f), k_as_f((ki)(1)), nn > 0.0f);
  return select(r, z, x == 0.0f);
}

#undef V3T
#define V3T pv3
WF_STAGE void wf_shade_pk_at(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n,
                             uint depth, uint sample, uint i) {
  if (i >= n) return;
  ku flags = kload(0, su + U_FLAGS * n + i);
  ki alive_in = (flags & F_ALIVE) != 0u;
  if (!any(alive_in)) return;
  __global const lc_params* P = params;
  uint seed = P->seed;
  ku pix = (ku)(i) + K_IOTA;
#define PLD(c) kload(0, st + (c)*n + i)
  pv3 ro = v3m(PLD(S_OX), PLD(S_OY), PLD(S_OZ)), rd = v3m(PLD(S_DX), PLD(S_DY), PLD(S_DZ));
  pv3 beta = v3m(PLD(S_BR), PLD(S_BG), PLD(S_BB)), L = v3m(PLD(S_LR), PLD(S_LG), PLD(S_LB));
  kf prev_pdf = PLD(S_PREV_PDF);
  ki prev_delta = (flags & F_PREV_DELTA) != 0u;
  pv3 prev_p = v3m(PLD(S_PPX), PLD(S_PPY), PLD(S_PPZ));
  kf ht = PLD(S_HT), b1 = PLD(S_HB1), b2 = PLD(S_HB2);
  ku prim = kload(0, su + U_PRIM * n + i);
  ki hitm = alive_in & (prim != LC_INVALID);
  ki alive = (ki)(0), shadow = (ki)(0);
  pv3 zero3 = v3m((kf)(0.0f), (kf)(0.0f), (kf)(0.0f));
  pv3 contrib = zero3, so = zero3, sd = zero3;
  kf stmax = (kf)(0.0f);
  if (any(hitm)) {
    pv3 v0, v1, v2;
    PK_GATHER3(v0, lc_triangle, triangles, prim, hitm, v0);
    PK_GATHER3(v1, lc_triangle, triangles, prim, hitm, v1);
    PK_GATHER3(v2, lc_triangle, triangles, prim, hitm, v2);
    ku mat, light;
    PK_GATHER1(mat, lc_triangle, triangles, prim, hitm, material, uint, ku);
    PK_GATHER1(light, lc_triangle, triangles, prim, hitm, light, uint, ku);
    kf b0 = 1.0f - b1 - b2;
    pv3 p = v3_add(v3_add(v3_s(v0, b0), v3_s(v1, b1)), v3_s(v2, b2));
    pv3 perr =
        v3_s(v3_add(v3_add(v3_abs(v3_s(v0, b0)), v3_abs(v3_s(v1, b1))), v3_abs(v3_s(v2, b2))),
             7.0f * LC_REAL_U * 1.0001f);
    pv3 ng = v3_norm(v3_cross(v3_sub(v1, v0), v3_sub(v2, v0)));
    ki front = v3_dot(rd, ng) < 0.0f;
    ng = pv3_sel(v3_neg(ng), ng, front);
    ki em = hitm & front & (light != LC_INVALID);
    if (any(em)) {
      pv3 Le;
      PK_GATHER3(Le, lc_material, materials, mat, em, emission);
      kf pdf_sel, area;
      PK_GATHER1(pdf_sel, lc_light, lights, light, em, pdf_select, float, kf);
      PK_GATHER1(area, lc_light, lights, light, em, area, float, kf);
      kf cos_l = -v3_dot(rd, ng);
      kf pdf_l = select((kf)(0.0f), pdf_sel * ht * ht / (cos_l * area), cos_l > 0.0f);
      kf w = select(pk_mis(prev_pdf, pdf_l), (kf)(1.0f), prev_delta);
      L = pv3_sel(L, v3_add(L, v3_s(v3_mul(beta, Le), w)), em);
    }
    pv3 ns = ng;
    kf wo_z = -v3_dot(rd, ns);
    ki cont = hitm & (wo_z > 0.0f) & (ki)(depth + 2 <= P->max_depth ? -1 : 0);
    if (any(cont)) {
      ku dim = (ku)(LC_DIM_BOUNCE + depth * LC_DIMS_PER_BOUNCE);
      ku smp = (ku)(sample), sd_ = (ku)(seed);
      pv3 albedo;
      PK_GATHER3(albedo, lc_material, materials, mat, cont, albedo);
      kf sgn = copysign((kf)(1.0f), ns.z), a = -1.0f / (sgn + ns.z), c = ns.x * ns.y * a;
      pv3 ft = v3m(1.0f + sgn * ns.x * ns.x * a, sgn * c, -sgn * ns.x);
      pv3 fb = v3m(c, sgn + ns.y * ns.y * a, -ns.y);
      kf dd = v3_dot(v3_abs(ng), perr) + 2.0f * v3_max(perr);
      pv3 ot = v3_add(p, v3_s(ng, dd));
      pv3 o = v3m(pk_nudge(ot.x, ng.x), pk_nudge(ot.y, ng.y), pk_nudge(ot.z, ng.z));
      kf us = pk_rand(pix, smp, dim + LC_DIM_LIGHT_SELECT, sd_);
      kf u1 = pk_rand(pix, smp, dim + LC_DIM_LIGHT_UV, sd_);
      kf u2 = pk_rand(pix, smp, dim + LC_DIM_LIGHT_UV + 1, sd_);
      /* light CDF search, WF_CDF_ITERS branch-free steps */
      ku lo = (ku)(0), hi = (ku)(P->num_lights - 1);
      for (int it = 0; it < WF_CDF_ITERS; ++it) {
        ku mid = (lo + hi) >> 1u;
        kf cm;
        for (int k = 0; k < WF_PK; ++k) KL(cm, k) = light_cdf[KLU(mid, k)];
        ki act = lo < hi, cc = cm <= us;
        lo = select(lo, mid + 1u, k_as_u(act & cc));
        hi = select(hi, mid, k_as_u(act & ~cc));
      }
      ku li = lo, lprim;
      PK_GATHER1(lprim, lc_light, lights, li, cont, prim, uint, ku);
      kf lpdf_sel, larea;
      PK_GATHER1(lpdf_sel, lc_light, lights, li, cont, pdf_select, float, kf);
      PK_GATHER1(larea, lc_light, lights, li, cont, area, float, kf);
      pv3 Lrad, l0, l1, l2;
      PK_GATHER3(Lrad, lc_light, lights, li, cont, intensity);
      PK_GATHER3(l0, lc_triangle, triangles, lprim, cont, v0);
      PK_GATHER3(l1, lc_triangle, triangles, lprim, cont, v1);
      PK_GATHER3(l2, lc_triangle, triangles, lprim, cont, v2);
      kf su_ = sqrt(u1), lb0 = 1.0f - su_, lb1 = u2 * su_;
      pv3 q = v3_add(v3_add(v3_s(l0, lb0), v3_s(l1, lb1)), v3_s(l2, 1.0f - lb0 - lb1));
      pv3 nl = v3_norm(v3_cross(v3_sub(l1, l0), v3_sub(l2, l0)));
      pv3 to = v3_sub(q, o);
      kf d2 = v3_dot(to, to), dist = sqrt(d2);
      pv3 wi = v3_div(to, dist);
      kf cos_l = -v3_dot(wi, nl);
      kf pdf = lpdf_sel * d2 / (cos_l * larea);
      kf wi_z = v3_dot(wi, ns);
      ki nee = cont & (dist > 0.0f) & (cos_l > 0.0f) & (pdf > 0.0f) & (v3_dot(wi, ng) > 0.0f) &
               (wi_z > 0.0f) & (v3_max(albedo) > 0.0f);
      kf w = pk_mis(pdf, wi_z * LC_INV_PI);
      contrib = pv3_sel(
          zero3, v3_s(v3_mul(v3_mul(beta, v3_s(albedo, LC_INV_PI)), Lrad), wi_z * w / pdf), nee);
      so = pv3_sel(zero3, o, nee);
      sd = pv3_sel(zero3, wi, nee);
      stmax = select(
          (kf)(0.0f),
          dist * (1.0f - LC_SHADOW_REL_MARGIN) - 8.0f * FLT_EPSILON * (v3_max(v3_abs(o)) + dist),
          nee);
      shadow = nee;
      kf ub1 = pk_rand(pix, smp, dim + LC_DIM_BSDF_UV, sd_);
      kf ub2 = pk_rand(pix, smp, dim + LC_DIM_BSDF_UV + 1, sd_);
      kf r = sqrt(ub1), x2 = 2.0f * ub2;
      kf lx = r * cospi(x2), ly = r * sinpi(x2), lz = sqrt(fmax(0.0f, 1.0f - ub1));
      kf bpdf = lz * LC_INV_PI;
      pv3 nwi = v3_norm(v3_add(v3_add(v3_s(ft, lx), v3_s(fb, ly)), v3_s(ns, lz)));
      pv3 nbeta = v3_mul(beta, albedo);
      kf qq = v3_max(nbeta);
      ki ok = cont & (bpdf > 0.0f) & (v3_dot(nwi, ng) > 0.0f) & (qq > 0.0f);
      ki rr = (ki)(depth + 2 > P->rr_depth ? -1 : 0) & (qq < 1.0f);
      kf urr = pk_rand(pix, smp, dim + LC_DIM_RR, sd_);
      ok &= ~(rr & (urr >= qq));
      beta = pv3_sel(beta, pv3_sel(nbeta, v3_div(nbeta, qq), rr), ok);
      prev_delta = select(prev_delta, (ki)(0), ok);
      prev_pdf = select(prev_pdf, bpdf, ok);
      ro = pv3_sel(ro, o, ok);
      prev_p = pv3_sel(prev_p, o, ok);
      rd = pv3_sel(rd, nwi, ok);
      alive = ok;
    }
  }
#define PST(c, v) kstore((v), 0, st + (c)*n + i)
  PST(S_LR, L.x);
  PST(S_LG, L.y);
  PST(S_LB, L.z);
  PST(S_BR, beta.x);
  PST(S_BG, beta.y);
  PST(S_BB, beta.z);
  PST(S_OX, ro.x);
  PST(S_OY, ro.y);
  PST(S_OZ, ro.z);
  PST(S_DX, rd.x);
  PST(S_DY, rd.y);
  PST(S_DZ, rd.z);
  PST(S_PREV_PDF, prev_pdf);
  PST(S_PPX, prev_p.x);
  PST(S_PPY, prev_p.y);
  PST(S_PPZ, prev_p.z);
  PST(S_SOX, so.x);
  PST(S_SOY, so.y);
  PST(S_SOZ, so.z);
  PST(S_SDX, sd.x);
  PST(S_SDY, sd.y);
  PST(S_SDZ, sd.z);
  PST(S_STMAX, stmax);
  PST(S_CR, contrib.x);
  PST(S_CG, contrib.y);
  PST(S_CB, contrib.z);
  ku nf = select((ku)(0u), (ku)(F_ALIVE), k_as_u(alive)) |
          select((ku)(0u), (ku)(F_PREV_DELTA), k_as_u(prev_delta)) |
          select((ku)(0u), (ku)(F_SHADOW), k_as_u(shadow));
  kstore(select(flags, nf, k_as_u(alive_in)), 0, su + U_FLAGS * n + i);
#undef V3T
#define V3T v3
}
__kernel void wf_shade_pk(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n,
                          uint depth, uint sample) {
  wf_shade_pk_at(params, nodes, leaves, triangles, tri_attrs, spheres, materials, lights, light_cdf,
                 textures, texels, st, su, n, depth, sample, (uint)get_global_id(0) * WF_PK);
}

/* ---- packet megakernel: WF_PK paths per work-item through the whole path loop ----
 * The stage functions above run back to back on the work-item's own rows of the state arrays
 * (which stay in the L1/L2 cache): per bounce, every live lane is traced by the renderer's
 * single-ray traversal (or, with WF_PK_PACKET_RAYS, all lanes at once by packet_trace), the
 * lanes are shaded together by wf_shade_pk_at, the shadow rays traced likewise. One launch
 * renders spp samples per pixel, as the megakernel does. */
/* same direction octant for every active ray of the packet (and at least WF_MINACT of them) */
#ifndef WF_MINACT
#define WF_MINACT 3
#endif
static inline int wf_coherent(__global const float* st, __global const uint* su, uint n, uint i0,
                              int shadow) {
  pi flags = pvload(0, (__global const int*)su + U_FLAGS * n + i0);
  pi act = shadow ? ((flags & (int)F_SHADOW) != 0) : ((flags & (int)F_ALIVE) != 0);
  int cnt = 0;
  for (int k = 0; k < WF_PK; ++k) cnt += act[k] != 0;
  if (cnt < WF_MINACT) return 0;
  uint bx = shadow ? S_SDX : S_DX;
  int ok = 1;
  for (uint a = 0; a < 3; ++a) {
    pf d = pvload(0, st + (bx + a) * n + i0);
    pi neg = d < 0.0f;
    ok &= !any(act & neg) || !any(act & ~neg);
  }
  return ok;
}
/* With packet rays: packet traversal for closest-hit rays at depths < WF_PD and for shadow rays
 * at depths < WF_SD (the others lane by lane through the renderer's bvh_trace), or, with
 * WF_COH, also for any packet whose active rays (at least WF_MINACT) share one direction octant
 * (wf_coherent). Default: packets at every depth. */
#ifndef WF_PD
#define WF_PD 100
#endif
#ifndef WF_SD
#define WF_SD 100
#endif
#ifndef WF_COH
#define WF_COH 0
#endif
#define WF_SCENE                                                                                \
  params, nodes, leaves, triangles, tri_attrs, spheres, materials, lights, light_cdf, textures, \
      texels
__kernel void pk_mega(LC_SCENE_KERNEL_ARGS, __global float* st, __global uint* su, uint n, uint spp,
                      __global float4* sum, __global float4* sumsq) {
  uint i = get_global_id(0) * WF_PK;
  if (i >= n) return;
  for (uint smp = 0; smp < spp; ++smp) {
    for (uint k = 0; k < WF_PK; ++k) wf_generate_at(WF_SCENE, st, su, n, smp, i + k);
    for (uint depth = 0; depth < params->max_depth; ++depth) {
#if defined(WF_PK_PACKET_RAYS) && WF_PACKET == WF_PK
      if (depth < WF_PD || (WF_COH && wf_coherent(st, su, n, i, 0)))
        wf_trace_packet_at(WF_SCENE, st, su, n, i);
      else
#endif
        for (uint k = 0; k < WF_PK; ++k) wf_trace_at(WF_SCENE, st, su, n, i + k);
      wf_shade_pk_at(WF_SCENE, st, su, n, depth, smp, i);
#if defined(WF_PK_PACKET_RAYS) && WF_PACKET == WF_PK
      if (depth < WF_SD || (WF_COH && wf_coherent(st, su, n, i, 1)))
        wf_shadow_packet_at(WF_SCENE, st, su, n, i);
      else
#endif
        for (uint k = 0; k < WF_PK; ++k) wf_shadow_at(WF_SCENE, st, su, n, i + k);
      uint any_alive = 0;
      for (uint k = 0; k < WF_PK; ++k) any_alive |= su[U_FLAGS * n + i + k] & F_ALIVE;
      if (!any_alive) break;
    }
    for (uint k = 0; k < WF_PK; ++k) wf_film_at(st, n, sum, sumsq, i + k);
  }
}
