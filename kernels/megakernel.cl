/* lucent: the megakernel. One work-item per pixel; each launch adds samples_per_pass samples per
 * pixel, starting at sample_offset, and writes their sum and sum of squares for the host to
 * accumulate. Features are switched on by defines chosen from the scene (LC_HAS_*, listed in
 * src/render/pack.cpp, feature_defines); a scene compiles only the code it uses. */
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

__kernel void lucent_render(__global const lc_params* params, __global const lc_bvh_node* nodes,
                            __global const lc_uint* prim_refs,
                            __global const lc_triangle* triangles,
                            __global const lc_triangle_attr* tri_attrs,
                            __global const lc_sphere* spheres,
                            __global const lc_material* materials,
                            __global const lc_light* lights, __global const float* light_cdf,
                            __global const lc_texture* textures, __global const float4* texels,
                            __global float4* out_sum, __global float4* out_sumsq,
                            __global lc_uint* counters) {
  lc_uint gid = (lc_uint)get_global_id(0);
  lc_uint width = params->width, height = params->height;
  if (gid >= width * height) return;
  lc_scene s;
  s.params = params;
  s.nodes = nodes;
  s.prim_refs = prim_refs;
  s.triangles = triangles;
  s.tri_attrs = tri_attrs;
  s.spheres = spheres;
  s.materials = materials;
  s.lights = lights;
  s.light_cdf = light_cdf;
  s.textures = textures;
  s.texels = texels;

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
    float3 L;
    lc_uint integrator = params->integrator;
    L = (float3)(0.0f);
#ifdef LC_HAS_INTEGRATOR_PATH
    if (integrator == LC_INTEGRATOR_PATH) L = integrator_path(&s, ray, &rng, &rays);
#endif
#ifdef LC_HAS_INTEGRATOR_WHITTED
    if (integrator == LC_INTEGRATOR_WHITTED) L = integrator_whitted(&s, ray, &rays);
#endif
#ifdef LC_HAS_INTEGRATOR_DIRECT
    if (integrator == LC_INTEGRATOR_DIRECT) L = integrator_direct(&s, ray, &rays);
#endif
#ifdef LC_HAS_INTEGRATOR_AOV
    if (integrator >= LC_INTEGRATOR_ALBEDO) L = integrator_aov(&s, ray, &rng, &rays);
#endif
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
