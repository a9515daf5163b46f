/* lucent test kernel: the device's light sampling (kernels/light/light.cl) against its pdfs, for
 * tests/test_kernel_light_sampling.cpp. Scene arguments as in kernels/megakernel.cl. */
/* clang-format off */
#include "generated/all_features.cl" /* every light type */
#include "shared/types.h"
#include "shared/rng.h"
#include "util/math.cl"
#include "scene/scene.cl"
#include "geom/interaction.cl"
#include "bvh/traverse.cl"
#include "light/light.cl"
/* clang-format on */

/* out[i] = (wi, pdf) of sample i from point p, pdf = -1 when no sample was produced */
__kernel void probe_light_sample(LC_SCENE_KERNEL_ARGS, float4 p, __global float4* out) {
  lc_scene s = LC_SCENE_FROM_KERNEL_ARGS;
  lc_uint i = (lc_uint)get_global_id(0);
  lc_light_sample ls;
  int ok = light_sample(&s, p.xyz, LC_INVALID, lc_rng_uniform(0u, i, 0u, 3u),
                        lc_rng_uniform(0u, i, 1u, 3u), lc_rng_uniform(0u, i, 2u, 3u),
                        lc_rng_uniform(0u, i, 3u, 3u), &ls);
  /* delta (point) lights have no density: reported as not produced */
  out[i] = ok && !ls.delta && ls.pdf > 0.0f ? (float4)(ls.wi, ls.pdf)
                                            : (float4)(0.0f, 0.0f, 0.0f, -1.0f);
}

/* out[i] = (wi, pdf) of the sample from point p with the numbers u[i] = (us, u1, u2, u3) */
__kernel void probe_light_sample_with(LC_SCENE_KERNEL_ARGS, float4 p, __global const float4* u,
                                      __global float4* out) {
  lc_scene s = LC_SCENE_FROM_KERNEL_ARGS;
  size_t i = get_global_id(0);
  lc_light_sample ls;
  int ok = light_sample(&s, p.xyz, LC_INVALID, u[i].x, u[i].y, u[i].z, u[i].w, &ls);
  out[i] = ok && !ls.delta && ls.pdf > 0.0f ? (float4)(ls.wi, ls.pdf)
                                            : (float4)(0.0f, 0.0f, 0.0f, -1.0f);
}

/* pdf[i]: the solid-angle density with which light_sample from p produces direction dirs[i],
 * summed over all lights (each light's own pdf, occlusion ignored), through the pdf functions
 * the integrator uses for MIS. */
__kernel void probe_light_pdf(LC_SCENE_KERNEL_ARGS, float4 p, __global const float4* dirs,
                              __global float* pdf) {
  lc_scene s = LC_SCENE_FROM_KERNEL_ARGS;
  size_t i = get_global_id(0);
  float3 d = normalize(dirs[i].xyz);
  float sum = 0.0f;
  for (lc_uint l = 0; l < params->num_lights; ++l) {
    __global const lc_light* L = &lights[l];
    if (L->type == LC_LIGHT_SPHERE) {
      __global const lc_sphere* sp = &spheres[L->p.sphere.sphere];
      float t = sphere_intersect(lc_load3(sp->center), sp->radius, p.xyz, d, 0.0f, INFINITY);
      if (t < INFINITY) sum += light_pdf(&s, l, p.xyz, d, t, 1.0f);
    } else if (L->type == LC_LIGHT_TRIANGLE) {
      __global const lc_triangle* tri = &triangles[L->p.triangle.triangle];
      float3 v0 = lc_load3(tri->v0), v1 = lc_load3(tri->v1), v2 = lc_load3(tri->v2);
      lc_tri_ray tr = triangle_ray_setup(d);
      float t, b1, b2;
      if (triangle_intersect(&tr, p.xyz, v0, v1, v2, 0.0f, INFINITY, &t, &b1, &b2)) {
        float3 n = normalize(cross(v1 - v0, v2 - v0));
        sum += light_pdf(&s, l, p.xyz, d, t, -dot(d, n));
      }
    } else if (L->type == LC_LIGHT_ENV || L->type == LC_LIGHT_ENV_MAP) {
      float e;
      env_radiance(&s, d, &e);
      sum += e;
    }
  }
  pdf[i] = sum;
}

/* out[i] = lc_cdf_search(cdf, n, u[i]): the index that light selection and environment maps pick */
__kernel void probe_cdf_search(__global const float* cdf, uint n, __global const float* u,
                               __global uint* out) {
  size_t i = get_global_id(0);
  out[i] = lc_cdf_search(cdf, n, u[i]);
}
