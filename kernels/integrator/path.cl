/* lucent kernel: integrators (docs/rendering-model.md). One call computes the radiance of one
 * camera sample; random numbers come from lc_rand(pixel, sample, dimension) with the dimension
 * layout of shared/rng.h. */
#ifndef LUCENT_INTEGRATOR_PATH_CL
#define LUCENT_INTEGRATOR_PATH_CL

typedef struct {
  lc_uint pixel, sample, seed;
} lc_rng;

static inline float lc_rand(const lc_rng* r, lc_uint dim) {
  return lc_rng_uniform(r->pixel, r->sample, dim, r->seed);
}

/* Power heuristic with beta = 2. */
static inline float mis_power(float a, float b) {
  if (isinf(a)) return 1.0f;
  float a2 = a * a, b2 = b * b;
  return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

/* Local shading frame around n. */
typedef struct {
  float3 t, b, n;
} lc_frame;
static inline lc_frame frame_from(float3 n) {
  lc_frame f;
  f.n = n;
  lc_onb(n, &f.t, &f.b);
  return f;
}
static inline float3 frame_to_local(const lc_frame* f, float3 v) {
  return (float3)(dot(v, f->t), dot(v, f->b), dot(v, f->n));
}
static inline float3 frame_to_world(const lc_frame* f, float3 v) {
  return v.x * f->t + v.y * f->b + v.z * f->n;
}

/* Unoccluded test from a spawned origin o towards a sampled light point (or direction) at
 * distance dist from o. Light samples are taken from o itself, not from the surface point: the
 * offset of o is large on huge spheres (it scales with their float precision), and a direction
 * computed from the surface point would, seen from o, pass just inside a sphere light near its
 * silhouette. */
/* Relative shortening of shadow rays (see shadow_visible): float's 2e-4, and for double about
 * 2e-4 times the ratio of the two epsilons (3.7e-13), rounded up. The sampled light point must
 * then be computed in lc_real throughout (kernels/light/light.cl): a float barycentric sum or a
 * float sin/cos pair puts it ~1e-7 off the light's surface, which this margin does not cover
 * (the Cornell box's NEE was 15% too dark in double until they were lc_real). */
#ifdef LC_DOUBLE
#define LC_SHADOW_REL_MARGIN 1e-12
#else
#define LC_SHADOW_REL_MARGIN 2e-4f
#endif

static inline int shadow_visible(const lc_scene* s, lc_real3 o, lc_real3 wi, lc_real dist,
                                 lc_uint* rays) {
  lc_ray sr;
  sr.o = o;
  sr.d = wi;
  ++*rays;
  /* stop short of the light's own surface by its position error: relative to the distance, and
   * a few ulps of the sampled point's coordinates (it is only known to those: at 1e4 from the
   * origin a point on a sphere light 2 away is 1e-3 off, 2.5 times 2e-4 dist, and the shadow ray
   * hit the light itself: 20% too dark, tests/test_stability_scene.cpp StabilityTranslateLight);
   * both margins scale with lc_real's precision */
  lc_real tmax = isinf(dist) ? (lc_real)INFINITY
                             : dist * (LC_REAL(1.0) - LC_SHADOW_REL_MARGIN) -
                                   LC_REAL(8.0) * LC_REAL_EPSILON * (lc_max3r(fabs(o)) + dist);
  return !scene_occluded(s, sr, tmax);
}

/* Sum over point lights of f * cos * I / r^2 (direct and whitted integrators). With diffuse_only
 * the BSDF is albedo / pi (whitted's diffuse term). */
static inline float3 point_lights_direct(const lc_scene* s, const lc_interaction* it, const lc_bsdf* b,
                                         const lc_frame* fr, float3 wo_l, int diffuse_only, lc_uint* rays) {
  float3 sum = (float3)(0.0f);
#ifdef LC_HAS_POINT_LIGHTS
  __global const lc_params* P = s->params;
  for (lc_uint i = 0; i < P->num_lights; ++i) {
    __global const lc_light* L = &s->lights[i];
    if (L->type != LC_LIGHT_POINT) continue;
    /* irradiance from the surface point itself; the shadow ray leaves from the offset origin
     * (a point light has no surface that the few-ulp parallel shift could graze) */
    lc_real3 o = lc_spawn_origin(it->p, it->perr, it->ng);
    lc_real3 to = lc_load3r(L->position) - it->p;
    lc_real d2 = dot(to, to);
    lc_real dist = sqrt(d2);
    lc_real3 wi = to / dist;
    if (dot(wi, it->ng) <= LC_REAL(0.0)) continue;
    float3 wi_l = frame_to_local(fr, lc_float3_from_real3(wi));
    if (wi_l.z <= 0.0f) continue;
    float3 f;
    if (diffuse_only) {
      f = b->albedo * LC_INV_PI;
    } else {
      float pdf;
      f = bsdf_eval(b, wo_l, wi_l, &pdf);
    }
    if (lc_max3(f) <= 0.0f) continue;
    lc_ray sr;
    sr.o = o;
    sr.d = wi;
    ++*rays;
    if (scene_occluded(s, sr, dist)) continue;
    sum += f * lc_load3(L->intensity) * (wi_l.z / (float)d2);
  }
#endif
  return sum;
}

static inline float3 integrator_path(const lc_scene* s, lc_ray ray, const lc_rng* rng, lc_uint* rays) {
  __global const lc_params* P = s->params;
  float3 L = (float3)(0.0f), beta = (float3)(1.0f);
  float prev_pdf = 0.0f;
  int prev_delta = 1; /* the camera ray: emitters count fully */
  lc_real3 prev_p = ray.o;
  for (lc_uint depth = 0;; ++depth) {
    lc_hit hit;
    ++*rays;
    const int no_mis = (P->flags & LC_FLAG_NO_MIS) != 0;
    if (!scene_intersect(s, ray, INFINITY, &hit)) {
      float pdf_l;
      float3 Le = env_radiance(s, lc_float3_from_real3(ray.d), &pdf_l);
      L += beta * Le * (prev_delta ? 1.0f : (no_mis ? 0.0f : mis_power(prev_pdf, pdf_l)));
      break;
    }
    lc_interaction it = interaction_from_hit(s, ray, &hit);
    __global const lc_material* m = &s->materials[it.material];
    if (it.front && it.light != LC_INVALID) {
      float3 Le = lc_load3(m->emission);
      float w = 1.0f;
      if (!prev_delta) {
        float pdf_l = light_pdf_area(s, it.light, prev_p, hit.t, dot(-ray.d, it.ng));
        w = no_mis ? 0.0f : mis_power(prev_pdf, pdf_l);
      }
      L += beta * Le * w;
    }
    if (depth + 2 > P->max_depth) break;
    lc_uint dim = LC_DIM_BOUNCE + depth * LC_DIMS_PER_BOUNCE;
    lc_bsdf b = bsdf_from_material(s, m, it.uv);
    lc_frame fr = frame_from(it.ns);
    float3 wo_l = frame_to_local(&fr, lc_float3_from_real3(-ray.d));
    if (wo_l.z <= 0.0f) break;

    /* next-event estimation, from the origin that the shadow ray will use */
    lc_real3 o = lc_spawn_origin(it.p, it.perr, it.ng);
    if (!bsdf_is_delta(&b) && P->num_lights > 0) {
      lc_light_sample ls;
      if (light_sample(s, o, lc_rand(rng, dim + LC_DIM_LIGHT_SELECT),
                       lc_rand(rng, dim + LC_DIM_LIGHT_UV), lc_rand(rng, dim + LC_DIM_LIGHT_UV + 1), &ls) &&
          ls.pdf > 0.0f && dot(ls.wi, it.ng) > LC_REAL(0.0)) {
        float3 wi_l = frame_to_local(&fr, lc_float3_from_real3(ls.wi));
        float pdf_b;
        float3 f = bsdf_eval(&b, wo_l, wi_l, &pdf_b);
        if (lc_max3(f) > 0.0f && shadow_visible(s, o, ls.wi, ls.dist, rays)) {
          float w = (ls.delta || no_mis) ? 1.0f : mis_power(ls.pdf, pdf_b);
          L += beta * f * ls.L * (wi_l.z * w / ls.pdf);
        }
      }
    }

    /* continue the path */
    lc_bsdf_sample bs;
    if (!bsdf_sample(&b, wo_l, it.front, lc_rand(rng, dim + LC_DIM_BSDF_LOBE),
                     lc_rand(rng, dim + LC_DIM_BSDF_UV), lc_rand(rng, dim + LC_DIM_BSDF_UV + 1), &bs))
      break;
    lc_real3 wi = normalize(lc_real3_from_float3(frame_to_world(&fr, bs.wi)));
    int transmit = bs.wi.z < 0.0f;
    lc_real side = dot(wi, it.ng);
    if (transmit ? side >= LC_REAL(0.0) : side <= LC_REAL(0.0)) break; /* shading normal leak */
    beta *= bs.weight;
    if (!(lc_max3(beta) > 0.0f)) break;
    prev_delta = bs.delta;
    prev_pdf = bs.pdf;
    ray.o = transmit ? lc_spawn_origin(it.p, it.perr, -it.ng) : o;
    prev_p = ray.o; /* light pdfs for MIS are evaluated from where light sampling sampled */
    ray.d = wi;
    /* Russian roulette: survive with probability max(beta) while it is below 1, so the
     * throughput after the division never exceeds 1 (a cap such as min(0.95, max(beta)) makes
     * beta grow like (albedo / 0.95)^n on albedos above 0.95: unbiased, infinite variance) */
    float q = lc_max3(beta);
    if (depth + 2 > P->rr_depth && q < 1.0f) {
      if (lc_rand(rng, dim + LC_DIM_RR) >= q) break;
      beta /= q;
    }
  }
  return L;
}

#define LC_WHITTED_STACK 32

typedef struct {
  lc_ray ray;
  float3 w;
  lc_uint segments; /* segments of the path including this ray */
} lc_whitted_entry;

/* Deterministic recursive ray tracing with an explicit stack (depth-first; at most one pending
 * sibling per level, so LC_WHITTED_STACK bounds max_depth). */
static inline float3 integrator_whitted(const lc_scene* s, lc_ray ray, lc_uint* rays) {
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
    lc_bsdf b = bsdf_from_material(s, m, it.uv);
    lc_frame fr = frame_from(it.ns);
    float3 wo_l = frame_to_local(&fr, lc_float3_from_real3(-e.ray.d));
    if (b.type == LC_MAT_DIFFUSE || b.type == LC_MAT_PLASTIC)
      L += e.w * point_lights_direct(s, &it, &b, &fr, wo_l, 1, rays);
    if (e.segments >= P->max_depth || b.type == LC_MAT_DIFFUSE || wo_l.z <= 0.0f) continue;
    lc_real3 refl =
        normalize(lc_real3_from_float3(frame_to_world(&fr, (float3)(-wo_l.x, -wo_l.y, wo_l.z))));
    float3 w_refl = (float3)(0.0f), w_refr = (float3)(0.0f);
    lc_real3 refr = (lc_real3)(LC_REAL(0.0));
    float ct;
    if (b.type == LC_MAT_MIRROR || b.type == LC_MAT_CONDUCTOR) {
      w_refl = b.specular;
    } else if (b.type == LC_MAT_PLASTIC) {
      w_refl = b.specular * fresnel_dielectric(wo_l.z, b.ior, &ct);
    } else if (b.type == LC_MAT_DIELECTRIC) {
      float eta = it.front ? b.ior : 1.0f / b.ior;
      float F = fresnel_dielectric(wo_l.z, eta, &ct);
      w_refl = (float3)(F);
      if (F < 1.0f) {
        w_refr = b.specular * (1.0f - F);
        refr = normalize(
            lc_real3_from_float3(frame_to_world(&fr, (float3)(-wo_l.x / eta, -wo_l.y / eta, -ct))));
      }
    }
    if (lc_max3(w_refr) > 0.0f && dot(refr, it.ng) < LC_REAL(0.0) && sp < LC_WHITTED_STACK) {
      stack[sp].ray.o = lc_spawn_origin(it.p, it.perr, -it.ng);
      stack[sp].ray.d = refr;
      stack[sp].w = e.w * w_refr;
      stack[sp].segments = e.segments + 1;
      ++sp;
    }
    if (lc_max3(w_refl) > 0.0f && dot(refl, it.ng) > LC_REAL(0.0) && sp < LC_WHITTED_STACK) {
      stack[sp].ray.o = lc_spawn_origin(it.p, it.perr, it.ng);
      stack[sp].ray.d = refl;
      stack[sp].w = e.w * w_refl;
      stack[sp].segments = e.segments + 1;
      ++sp;
    }
  }
  return L;
}

/* Emission at the first hit plus point lights through the full BSDF. */
static inline float3 integrator_direct(const lc_scene* s, lc_ray ray, lc_uint* rays) {
  lc_hit hit;
  ++*rays;
  if (!scene_intersect(s, ray, INFINITY, &hit)) {
    float pdf;
    return env_radiance(s, lc_float3_from_real3(ray.d), &pdf);
  }
  lc_interaction it = interaction_from_hit(s, ray, &hit);
  __global const lc_material* m = &s->materials[it.material];
  float3 L = it.front ? lc_load3(m->emission) : (float3)(0.0f);
  lc_bsdf b = bsdf_from_material(s, m, it.uv);
  lc_frame fr = frame_from(it.ns);
  float3 wo_l = frame_to_local(&fr, lc_float3_from_real3(-ray.d));
  if (wo_l.z > 0.0f && !bsdf_is_delta(&b)) L += point_lights_direct(s, &it, &b, &fr, wo_l, 0, rays);
  return L;
}

/* Arbitrary output variables of the first hit. */
static inline float3 integrator_aov(const lc_scene* s, lc_ray ray, const lc_rng* rng, lc_uint* rays) {
  __global const lc_params* P = s->params;
  lc_hit hit;
  ++*rays;
  if (!scene_intersect(s, ray, INFINITY, &hit)) return (float3)(0.0f);
  lc_interaction it = interaction_from_hit(s, ray, &hit);
  if (P->integrator == LC_INTEGRATOR_DEPTH) return (float3)((float)hit.t);
  if (P->integrator == LC_INTEGRATOR_PRIMITIVE) {
    /* scene order: spheres first, then the scene's triangle list (exact in float below 2^24) */
    lc_uint id = (hit.prim & LC_PRIM_SPHERE_BIT) ? (hit.prim & ~LC_PRIM_SPHERE_BIT)
                                                 : P->num_spheres + s->tri_attrs[hit.prim].source_index;
    return (float3)((float)(id + 1u));
  }
  if (P->integrator == LC_INTEGRATOR_NORMAL) return it.ns;
  __global const lc_material* m = &s->materials[it.material];
  lc_bsdf b = bsdf_from_material(s, m, it.uv);
  if (P->integrator == LC_INTEGRATOR_ALBEDO) return bsdf_albedo_aov(&b);
  /* ambient occlusion */
  lc_frame fr = frame_from(it.ns);
  float3 wi = frame_to_world(&fr, sample_cosine_hemisphere(lc_rand(rng, LC_DIM_BOUNCE + LC_DIM_BSDF_UV),
                                                             lc_rand(rng, LC_DIM_BOUNCE + LC_DIM_BSDF_UV + 1)));
  lc_real3 wir = lc_real3_from_float3(wi);
  if (dot(wir, it.ng) <= LC_REAL(0.0)) return (float3)(0.0f);
  lc_ray sr;
  sr.o = lc_spawn_origin(it.p, it.perr, it.ng);
  sr.d = normalize(wir);
  ++*rays;
  return scene_occluded(s, sr, P->ao_distance) ? (float3)(0.0f) : (float3)(1.0f);
}

#endif
