/* lucent test and benchmark kernel: traces a buffer of rays through the real scene traversal
 * (bvh/traverse.cl) and returns what it found. Used by tests/test_bvh_trace.cpp (against a brute
 * force reference on the host) and bench/ (rays per second).
 *   rays[2 i]     = (origin, tmax)      rays[2 i + 1] = (direction, unused)
 *   hits[i]       = (t, as_float(prim), b1, b2); prim = LC_INVALID on a miss. With any_hit set
 *                   only the occlusion answer is meaningful: prim != LC_INVALID when occluded.
 * lucent_trace_info writes which form of the traversal this build compiled: info[0] = 1 with the
 * mask reductions of PoCL's x86-64 CPU device (LC_BVH_MOVMSK), 0 with the portable ones. */
/* clang-format off */
#include "shared/types.h"
#include "util/math.cl"
#include "scene/scene.cl"
#include "geom/interaction.cl"
#include "bvh/traverse.cl"
/* clang-format on */

__kernel void lucent_trace_rays(__global const lc_params* params, __global const lc_bvh_node* nodes,
                                __global const lc_bvh_leaf* leaves,
                                __global const lc_triangle* triangles,
                                __global const lc_sphere* spheres, __global const float4* rays,
                                __global float4* hits, lc_uint count, lc_uint any_hit) {
  lc_uint i = (lc_uint)get_global_id(0);
  if (i >= count) return;
  lc_scene s = lc_scene_geometry(params, nodes, leaves, triangles, spheres);
  float4 a = rays[2 * i], b = rays[2 * i + 1];
  lc_ray ray;
  ray.o = lc_real3_from_float3(a.xyz);
  ray.d = lc_real3_from_float3(b.xyz);
  lc_hit hit;
  if (any_hit) {
    int occluded = scene_occluded(&s, ray, a.w);
    hits[i] = (float4)(0.0f, as_float(occluded ? 0u : LC_INVALID), 0.0f, 0.0f);
  } else {
    scene_intersect(&s, ray, a.w, &hit);
    hits[i] = (float4)((float)hit.t, as_float(hit.prim), (float)hit.b1, (float)hit.b2);
  }
}

__kernel void lucent_trace_info(__global int* info) {
#ifdef LC_BVH_MOVMSK
  info[0] = 1;
#else
  info[0] = 0;
#endif
}
