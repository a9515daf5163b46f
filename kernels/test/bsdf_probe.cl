/* lucent test kernel: evaluates the device's Fresnel and BSDF code, the unit circle its sampling
 * uses, and the shading frame's directions, on inputs given by the host
 * (tests/test_kernel_bsdf.cpp). */
/* clang-format off */
#include "generated/all_features.cl" /* every material type */
#include "shared/types.h"
#include "shared/rng.h"
#include "util/math.cl"
#include "scene/scene.cl"
#include "geom/interaction.cl"
#include "bvh/traverse.cl"
#include "texture/texture.cl"
#include "bsdf/fresnel.cl"
#include "bsdf/microfacet.cl"
#include "bsdf/bsdf.cl"
#include "light/light.cl"
#include "integrator/common.cl"
/* clang-format on */

/* lc_unit_circle (util/math.cl) of each u */
__kernel void probe_unit_circle(__global const float* u, __global float2* out) {
  size_t i = get_global_id(0);
  out[i] = lc_unit_circle(u[i]);
}

/* in: (cos_i, eta) pairs; out: (F, cos_t) pairs */
__kernel void probe_fresnel(__global const float2* in, __global float2* out) {
  size_t i = get_global_id(0);
  float ct;
  float F = fresnel_dielectric(in[i].x, in[i].y, &ct);
  out[i] = (float2)(F, ct);
}

/* Samples `n` directions of the material for wo and returns (wi.xyz, pdf) and (weight.xyz,
 * delta) per sample; random numbers from the shared RNG with pixel = 0, sample = index. */
__kernel void probe_bsdf_sample(__global const lc_material* mat, float4 wo_in, int front,
                                __global float4* out_wi, __global float4* out_weight) {
  lc_uint i = (lc_uint)get_global_id(0);
  lc_bsdf b = bsdf_from_material_untextured(mat);
  b.front = front;
  lc_bsdf_sample bs;
  float3 wo = normalize(wo_in.xyz);
  int ok = bsdf_sample(&b, wo, lc_rng_uniform(0u, i, 0u, 7u), lc_rng_uniform(0u, i, 1u, 7u),
                       lc_rng_uniform(0u, i, 2u, 7u), &bs);
  out_wi[i] = ok ? (float4)(bs.wi, bs.pdf) : (float4)(0.0f, 0.0f, 0.0f, -1.0f);
  out_weight[i] = ok ? (float4)(bs.weight, (float)bs.delta) : (float4)(0.0f);
}

/* Evaluates f and pdf for (wo, wi) pairs, wo on the outside (front = 1) or inside. */
__kernel void probe_bsdf_eval(__global const lc_material* mat, __global const float4* wo_in,
                              __global const float4* wi_in, __global float4* out, int front) {
  size_t i = get_global_id(0);
  lc_bsdf b = bsdf_from_material_untextured(mat);
  b.front = front;
  float pdf;
  float3 f = bsdf_eval(&b, wo_in[i].xyz, wi_in[i].xyz, &pdf);
  out[i] = (float4)(f, pdf);
}

/* The next ray's direction as the path integrator makes it (integrator/common.cl): in (n.xyz, u1,
 * u2, steps, -, -) with n a unit normal. out.s012: frame_to_world_dir of the cosine-distributed
 * direction of (u1, u2) in the frame of n; out.s3: that direction's local z. out.s456: the
 * direction after `steps` more bounces off mirrors, each in a frame of its own (a normal between
 * the reversed direction and a random one, as interaction_from_hit's: normalised in float), wo
 * taken with frame_to_local and mirrored as the mirror BSDF does; no step normalises it again. */
__kernel void probe_frame_dir(__global const float8* in, __global float8* out) {
  lc_uint i = (lc_uint)get_global_id(0);
  float8 a = in[i];
  lc_frame fr = frame_from(a.s012);
  float3 wl = sample_cosine_hemisphere(a.s3, a.s4);
  lc_real3 w = frame_to_world_dir(&fr, wl);
  lc_real3 d = w;
  for (int k = 0; k < (int)a.s5; ++k) {
    float3 r = sample_cosine_hemisphere(lc_rng_uniform(i, (lc_uint)k, 0u, 11u),
                                        lc_rng_uniform(i, (lc_uint)k, 1u, 11u));
    float3 m = -lc_float3_from_real3(d) + 0.9f * r; /* |0.9 r| < |d|: m faces -d */
    float len = length(m);
    if (!(len > 0.0f)) continue;
    lc_frame f = frame_from(m / len);
    float3 wo = frame_to_local(&f, lc_float3_from_real3(-d));
    if (wo.z <= 0.0f) continue;
    d = frame_to_world_dir(&f, (float3)(-wo.x, -wo.y, wo.z));
  }
  out[i] = (float8)(lc_float3_from_real3(w), wl.z, lc_float3_from_real3(d), 0.0f);
}
