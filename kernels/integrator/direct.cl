/* lucent kernel: the direct integrator: emission at the first hit plus point lights. */
#ifndef LUCENT_INTEGRATOR_DIRECT_CL
#define LUCENT_INTEGRATOR_DIRECT_CL

/* Emission at the first hit plus point lights through the full BSDF. */
static inline float3 integrator_direct(const lc_scene* s, lc_ray ray, const lc_rng* rng,
                                       lc_uint* rays) {
  lc_hit hit;
  ++*rays;
  if (!scene_intersect(s, ray, INFINITY, &hit)) {
    float pdf;
    return env_radiance(s, lc_float3_from_real3(ray.d), &pdf);
  }
  lc_interaction it = interaction_from_hit(s, ray, &hit);
  __global const lc_material* m = &s->materials[it.material];
  float3 L = it.front ? lc_load3(m->emission) : (float3)(0.0f);
  lc_bsdf b = bsdf_from_material(s, m, it.uv, it.front);
  lc_frame fr = frame_from(it.ns);
  float3 wo_l = frame_to_local(&fr, lc_float3_from_real3(-ray.d));
  if (wo_l.z > 0.0f && !bsdf_is_delta(&b))
    L += point_lights_direct(s, &it, &b, (float3)(0.0f), &fr, wo_l, rays);
  return L;
}

#endif
