/* lucent: the megakernel. One work-item per pixel (or per entry of an adaptive pass's work list);
 * each launch adds samples_per_pass samples per pixel, starting at sample_offset (or the entry's
 * samples), and writes their sum and sum of squares for the host to accumulate. Features are
 * switched on by defines chosen from the scene (LC_HAS_*: the feature column of shared/registry.h
 * and src/render/features.cpp); a scene compiles only the code it uses. */
/* clang-format off */
#include "shared/types.h"
#include "shared/rng.h"
#include "util/math.cl"
#include "scene/scene.cl"
#include "sampler/sampler.cl"
#include "geom/interaction.cl"
#include "bvh/traverse.cl"
#include "texture/texture.cl"
#include "film/filter.cl"
#include "camera/camera.cl"
#include "bsdf/fresnel.cl"
#include "bsdf/microfacet.cl"
#include "bsdf/bsdf.cl"
#include "light/light.cl"
#include "integrator/integrator.cl"
/* clang-format on */

/* The work list of an adaptive pass (params->work_items > 0): entry i = (pixel, first sample,
 * number of samples, stream) for work-item i, whose sums go to out_sum[i], out_sumsq[i]; stream
 * s draws with the seed lc_stream_seed(seed, s) (shared/rng.h). Without a work list, work-item i
 * is pixel i and renders samples [sample_offset, sample_offset + samples_per_pass) with the seed.
 * Either way a sample's random numbers depend only on its pixel, index and seed. With
 * integrator.caustics each camera sample also traces a light path that adds to light_sum and
 * light_sumsq, any pixel's (integrator/caustics.cl): a uniform pass's to elements [0, W H), a
 * work list's stream s < 2 to elements [s W H, (s + 1) W H) (the adaptive halves' separate light
 * estimates); stream 2, the calibration's, traces none. Work-item i also writes the sum and the
 * sum of squares of its light paths' totals (a path's shares over all pixels) after the items'
 * sums, to out_sum[items + i] and out_sumsq[items + i] (items: the work list's entries or W H),
 * for the host to add up: the image mean's light part, whose variance no pixel's variance shows
 * (a path's splats correlate the pixels; docs/compare.md).
 * vec_type_hint(float4): one work-item is one path, written with vector types; an OpenCL compiler
 * that packs work-items into SIMD lanes (Intel's CPU runtime does when its cost model says so)
 * should not. Intel's CPU runtime 2026.2 packed them for small kernels (the AOV integrators) and
 * then found spheres at t ~ 1e-7 in a scene of spheres and triangles; forced to pack the path
 * tracer, it rendered 2-4x slower (BENCHMARKS.md, "Intel's CPU OpenCL runtime"). PoCL and GPU
 * drivers ignore the hint. */
/* Adds v to the 64-bit count of counters[low] and counters[high] (shared/types.h): the add whose
 * old value plus v wraps past 2^32 carries one into the high word. */
static inline void lc_count64(__global lc_uint* counters, int low, int high, lc_uint v) {
  const lc_uint old = atomic_add(&counters[low], v);
  if (old + v < old) atomic_inc(&counters[high]);
}

/* A pass's per-pixel sums: in double where the host defines LC_ACCUM_DOUBLE (devices with fp64,
 * src/render/features.cpp), so that how a render's samples fall into passes (which follows the
 * passes' measured times) changes its sums only in double rounding, far below what the float
 * image keeps: a render with more than one pass is then the same image from run to run. In
 * float otherwise (where the check below rejects samples by the pass's sum of squares). A
 * sample's square of floats is exact in double. */
#ifdef LC_ACCUM_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double lc_accum;
typedef double3 lc_accum3;
typedef double4 lc_accum4;
#define lc_accum3_from(v) convert_double3(v)
#define lc_accum_float3(v) convert_float3(v)
#else
typedef float lc_accum;
typedef float3 lc_accum3;
typedef float4 lc_accum4;
#define lc_accum3_from(v) (v)
#define lc_accum_float3(v) (v)
#endif
#ifndef LC_HAS_CAUSTICS
typedef float4 lc_lsum4; /* the light sums' element (integrator/caustics.cl): unused here */
#endif

__kernel __attribute__((vec_type_hint(float4))) void lucent_render(
    LC_SCENE_KERNEL_ARGS, __global const uint4* work, __global lc_accum4* out_sum,
    __global lc_accum4* out_sumsq, __global lc_uint* counters, __global lc_lsum4* light_sum,
    __global lc_lsum4* light_sumsq) {
  lc_uint gid = (lc_uint)get_global_id(0);
  lc_uint width = params->width, height = params->height;
  lc_rng rng;
  lc_uint pixel, first, count;
#ifdef LC_HAS_CAUSTICS
  lc_uint light_base = 0u; /* the light sums' first element for this work-item's stream */
  int trace_light = 1;
#endif
  if (params->work_items > 0u) {
    if (gid >= params->work_items) return;
    uint4 e = work[gid];
    pixel = e.x;
    first = e.y;
    count = e.z;
    lc_rng_init(&rng, pixel, lc_stream_seed(params->seed, e.w), params->sampler);
#ifdef LC_HAS_CAUSTICS
    trace_light = e.w < 2u;
    light_base = trace_light ? e.w * width * height : 0u;
#endif
  } else {
    if (gid >= width * height) return;
    pixel = gid;
    first = params->sample_offset;
    count = params->samples_per_pass;
    lc_rng_init(&rng, pixel, params->seed, params->sampler);
  }
  lc_scene s = LC_SCENE_FROM_KERNEL_ARGS;

  lc_uint px = pixel % width, py = pixel / width;
  lc_accum3 sum = (lc_accum3)(0.0f), sumsq = (lc_accum3)(0.0f);
  lc_uint accepted = 0, nonfinite = 0, rays = 0;
#ifdef LC_HAS_CAUSTICS
  lc_accum3 total_sum = (lc_accum3)(0.0f), total_sumsq = (lc_accum3)(0.0f);
#endif
  for (lc_uint k = 0; k < count; ++k) {
    lc_rng_set_sample(&rng, first + k);
    float2 uf = lc_rand2(&rng, LC_DIM_FILTER);
    float2 off = filter_sample(params->filter, params->filter_radius, uf.x, uf.y);
#ifdef LC_HAS_THIN_LENS
    float2 ul = lc_rand2(&rng, LC_DIM_LENS);
#else
    float2 ul = (float2)(0.0f);
#endif
    lc_ray ray = camera_generate_ray(&params->camera, (float)px + 0.5f + off.x,
                                     (float)py + 0.5f + off.y, width, height, ul.x, ul.y);
    float3 L = integrate(&s, ray, &rng, &rays);
#ifdef LC_HAS_CAUSTICS
    if ((params->flags & LC_FLAG_CAUSTICS) && trace_light) {
      lc_lsum3 total;
      nonfinite += caustics_light_path(&s, &rng, light_sum + light_base, light_sumsq + light_base,
                                       &total, &rays);
      lc_accum3 t = lc_accum3_from(total);
      total_sum += t;
      total_sumsq += t * t;
    }
#endif
    /* a sample whose square overflows float counts as non-finite too: an infinite sum of squares
     * made the variance infinite, sent every pixel of an adaptive render to its cap and wrote part
     * files that merge refused. In double, a pass's sums cannot overflow: each sample is judged
     * alone (judged by the pass's sum, the bright samples of a lamp's edge were dropped and the
     * dark kept: a lamp of 1e17 rendered 4.4% dark); in float, by the pass's sum of squares. */
    lc_accum3 l = lc_accum3_from(L), sq = l * l;
#ifdef LC_ACCUM_DOUBLE
    if (lc_isfinite3(L) && lc_isfinite3(L * L)) {
#else
    if (lc_isfinite3(L) && lc_isfinite3(sumsq + sq)) {
#endif
      sum += l;
      sumsq += sq;
      ++accepted;
    } else {
      ++nonfinite;
    }
  }
  out_sum[gid] = (lc_accum4)(sum, (lc_accum)accepted);
  out_sumsq[gid] = (lc_accum4)(sumsq, (lc_accum)0.0f);
#ifdef LC_HAS_CAUSTICS
  if (params->flags & LC_FLAG_CAUSTICS) {
    const lc_uint items = params->work_items > 0u ? params->work_items : width * height;
    out_sum[items + gid] = (lc_accum4)(total_sum, (lc_accum)0.0f);
    out_sumsq[items + gid] = (lc_accum4)(total_sumsq, (lc_accum)0.0f);
  }
#endif
  if (nonfinite) lc_count64(counters, LC_COUNTER_NONFINITE, LC_COUNTER_NONFINITE_HIGH, nonfinite);
  lc_count64(counters, LC_COUNTER_RAYS, LC_COUNTER_RAYS_HIGH, rays);
}
