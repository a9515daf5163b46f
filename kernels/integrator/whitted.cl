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

/* Deterministic recursive ray tracing with an explicit stack, depth first. A branch point leaves
 * its heavier branch waiting, and the lighter one's weight is at most half the ray's (F and
 * (1 - F) tint: the dielectrics' Whitted lobes; the other materials' have one branch). With m
 * branches waiting, a ray's weight is at most 2^-m, and a ray under 1e-9 is cut before it
 * branches: at most 29 wait below a branching ray, which leaves its two above them, so the stack
 * of 32 never fills, however deep max_depth is. Only weights above 1 (a tint or reflectance
 * above 1, which validate_scene warns about) can fill it; then the branches that do not fit are
 * dropped. */
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
    /* branches too faint to matter are cut, as the reference cuts them */
    if (lc_max3(e.w) < 1e-9f) continue;
    lc_bsdf b = bsdf_from_material(s, m, it.uv, it.front);
    lc_frame fr = frame_from(it.ns);
    float3 wo_l = frame_to_local(&fr, lc_float3_from_real3(-e.ray.d));
    lc_whitted_bsdf w = bsdf_whitted(&b, wo_l);
    if (w.diffuse_lobe) L += e.w * point_lights_direct(s, &it, 0, w.diffuse, &fr, wo_l, rays);
    if (wo_l.z <= 0.0f) continue;
    if (!(lc_max3(w.reflect) > 0.0f) && !(lc_max3(w.transmit) > 0.0f)) continue;
    lc_whitted_entry br[2];
    int n = 0;
    if (lc_max3(w.transmit) > 0.0f) {
      lc_real3 refr = frame_to_world_dir(&fr, w.transmit_wi);
      if (dot(refr, it.ng) < LC_REAL(0.0)) {
        br[n].ray.o = lc_spawn_origin(it.p, it.perr, -it.ng);
        br[n].ray.d = refr;
        br[n].w = e.w * w.transmit;
        br[n].segments = e.segments + 1;
        ++n;
      }
    }
    lc_real3 refl = frame_to_world_dir(&fr, (float3)(-wo_l.x, -wo_l.y, wo_l.z));
    if (lc_max3(w.reflect) > 0.0f && dot(refl, it.ng) > LC_REAL(0.0)) {
      br[n].ray.o = lc_spawn_origin(it.p, it.perr, it.ng);
      br[n].ray.d = refl;
      br[n].w = e.w * w.reflect;
      br[n].segments = e.segments + 1;
      ++n;
    }
    /* the lighter branch goes on top, to be traced first, so that the heavier one waits */
    if (n == 2 && lc_max3(w.reflect) > lc_max3(w.transmit)) {
      lc_whitted_entry t = br[0];
      br[0] = br[1];
      br[1] = t;
    }
    for (int k = 0; k < n && sp < LC_WHITTED_STACK; ++k) stack[sp++] = br[k];
  }
  return L;
}

#endif
