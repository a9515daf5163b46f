/* lucent: the megakernel. One work-item per pixel; each launch adds samples_per_pass samples per
 * pixel, starting at sample_offset, and writes their sum and sum of squares for the host to
 * accumulate. Features are switched on by defines chosen from the scene (LC_HAS_*: the feature
 * column of shared/registry.h and src/render/features.cpp); a scene compiles only the code it
 * uses. */
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

__kernel void lucent_render(LC_SCENE_KERNEL_ARGS, __global float4* out_sum,
                            __global float4* out_sumsq, __global lc_uint* counters) {
  lc_uint gid = (lc_uint)get_global_id(0);
  lc_uint width = params->width, height = params->height;
  if (gid >= width * height) return;
  lc_scene s = LC_SCENE_FROM_KERNEL_ARGS;

  lc_uint px = gid % width, py = gid / width;
  float3 sum = (float3)(0.0f), sumsq = (float3)(0.0f);
  lc_uint accepted = 0, nonfinite = 0, rays = 0;
  for (lc_uint k = 0; k < params->samples_per_pass; ++k) {
    lc_rng rng;
    rng.pixel = gid;
    rng.sample = params->sample_offset + k;
    rng.seed = params->seed;
    float2 off = filter_sample(params->filter, params->filter_radius, lc_rand(&rng, LC_DIM_FILTER),
                               lc_rand(&rng, LC_DIM_FILTER + 1));
    lc_ray ray = camera_generate_ray(&params->camera, (float)px + 0.5f + off.x,
                                     (float)py + 0.5f + off.y, width, height,
                                     lc_rand(&rng, LC_DIM_LENS), lc_rand(&rng, LC_DIM_LENS + 1));
    float3 L = integrate(&s, ray, &rng, &rays);
    if (lc_isfinite3(L)) {
      sum += L;
      sumsq += L * L;
      ++accepted;
    } else {
      ++nonfinite;
    }
  }
  out_sum[gid] = (float4)(sum, (float)accepted);
  out_sumsq[gid] = (float4)(sumsq, 0.0f);
  if (nonfinite) atomic_add(&counters[LC_COUNTER_NONFINITE], nonfinite);
  atomic_add(&counters[LC_COUNTER_RAYS], rays);
}
