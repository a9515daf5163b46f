/* lucent kernel: the Whitted integrator: deterministic classic ray tracing. Every BSDF is seen
 * through bsdf_whitted (bsdf/bsdf.cl): a lambertian part lit by point lights, a mirror reflection
 * and a refraction with fixed weights. */
#ifndef LUCENT_INTEGRATOR_WHITTED_CL
#define LUCENT_INTEGRATOR_WHITTED_CL

#define LC_WHITTED_STACK 32

typedef struct {
  lc_ray ray;
  float3 w;
  lc_uint segments; /* segments of the path including this ray */
} lc_whitted_entry;

/* Deterministic recursive ray tracing with an explicit stack (depth-first; at most one pending
 * sibling per level, so LC_WHITTED_STACK bounds max_depth). */
static inline float3 integrator_whitted(const lc_scene* s, lc_ray ray, const lc_rng* rng,
                                        lc_uint* rays) {
  __global const lc_params* P = s->params;
  lc_whitted_entry stack[LC_WHITTED_STACK];
  int sp = 0;
  stack[sp].ray = ray;
  stack[sp].w = (float3)(1.0f);
  stack[sp].segments = 1;
  ++sp;
  float3 L = (float3)(0.0f);
  while (sp > 0) {
    lc_whitted_entry e = stack[--sp];
    lc_hit hit;
    ++*rays;
    if (!scene_intersect(s, e.ray, INFINITY, &hit)) {
      float pdf;
      L += e.w * env_radiance(s, lc_float3_from_real3(e.ray.d), &pdf);
      continue;
    }
    lc_interaction it = interaction_from_hit(s, e.ray, &hit);
    __global const lc_material* m = &s->materials[it.material];
    if (it.front) L += e.w * lc_load3(m->emission);
    /* max_depth counts segments: a point light's shadow ray would be one more */
    if (e.segments >= P->max_depth) continue;
    lc_bsdf b = bsdf_from_material(s, m, it.uv, it.front);
    lc_frame fr = frame_from(it.ns);
    float3 wo_l = frame_to_local(&fr, lc_float3_from_real3(-e.ray.d));
    lc_whitted_bsdf w = bsdf_whitted(&b, wo_l);
    if (w.diffuse_lobe) L += e.w * point_lights_direct(s, &it, 0, w.diffuse, &fr, wo_l, rays);
    if (wo_l.z <= 0.0f) continue;
    if (!(lc_max3(w.reflect) > 0.0f) && !(lc_max3(w.transmit) > 0.0f)) continue;
    if (lc_max3(w.transmit) > 0.0f && sp < LC_WHITTED_STACK) {
      lc_real3 refr = frame_to_world_dir(&fr, w.transmit_wi);
      if (dot(refr, it.ng) < LC_REAL(0.0)) {
        stack[sp].ray.o = lc_spawn_origin(it.p, it.perr, -it.ng);
        stack[sp].ray.d = refr;
        stack[sp].w = e.w * w.transmit;
        stack[sp].segments = e.segments + 1;
        ++sp;
      }
    }
    lc_real3 refl = frame_to_world_dir(&fr, (float3)(-wo_l.x, -wo_l.y, wo_l.z));
    if (lc_max3(w.reflect) > 0.0f && dot(refl, it.ng) > LC_REAL(0.0) && sp < LC_WHITTED_STACK) {
      stack[sp].ray.o = lc_spawn_origin(it.p, it.perr, it.ng);
      stack[sp].ray.d = refl;
      stack[sp].w = e.w * w.reflect;
      stack[sp].segments = e.segments + 1;
      ++sp;
    }
  }
  return L;
}

#endif
