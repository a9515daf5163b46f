/* lucent kernel: integrators. One work-item computes the radiance of one camera sample. */
#ifndef LUCENT_INTEGRATOR_PATH_CL
#define LUCENT_INTEGRATOR_PATH_CL

static inline float lc_rand(lc_uint pixel, lc_uint sample, lc_uint dim, lc_uint seed) {
  return lc_rng_uniform(pixel, sample, dim, seed);
}

static inline float3 material_albedo(const lc_scene* s, __global const lc_material* m, float2 uv) {
  float3 a = lc_load3(m->albedo);
#ifdef LC_HAS_TEXTURES
  if (m->albedo_tex >= 0) a = texture_lookup(s, m->albedo_tex, uv).xyz;
#endif
  return a;
}

/* Direct light from every point light at it, for a Lambertian surface of albedo a. */
static inline float3 light_point_direct(const lc_scene* s, const lc_interaction* it, float3 albedo) {
  float3 sum = (float3)(0.0f);
  __global const lc_params* P = s->params;
  for (lc_uint i = 0; i < P->num_lights; ++i) {
    __global const lc_light* L = &s->lights[i];
    if (L->type != LC_LIGHT_POINT) continue;
    float3 to = lc_load3(L->position) - it->p;
    float d2 = dot(to, to);
    float dist = sqrt(d2);
    float3 wi = to / dist;
    float cos_s = dot(wi, it->ns);
    if (cos_s <= 0.0f || dot(wi, it->ng) <= 0.0f) continue;
    lc_ray sr;
    sr.o = lc_spawn_origin(it->p, it->perr, it->ng);
    sr.d = wi;
    if (scene_occluded(s, sr, dist)) continue;
    sum += lc_load3(L->intensity) * (cos_s / d2);
  }
  return albedo * LC_INV_PI * sum;
}

static inline float3 integrator_path(const lc_scene* s, lc_ray ray, lc_uint pixel, lc_uint sample,
                                     lc_uint* rays) {
  __global const lc_params* P = s->params;
  float3 L = (float3)(0.0f), beta = (float3)(1.0f);
  for (lc_uint depth = 0;; ++depth) {
    lc_hit hit;
    ++*rays;
    if (!scene_intersect(s, ray, INFINITY, &hit)) {
      L += beta * lc_load3(P->env_radiance);
      break;
    }
    lc_interaction it = interaction_from_hit(s, ray, &hit);
    __global const lc_material* m = &s->materials[it.material];
    if (it.front) L += beta * lc_load3(m->emission);
    if (depth + 1 >= P->max_depth) break;
    lc_uint dim = LC_DIM_BOUNCE + depth * LC_DIMS_PER_BOUNCE;
    float3 albedo = material_albedo(s, m, it.uv);
    if (m->type == LC_MAT_MIRROR) {
      beta *= lc_load3(m->specular);
      ray.d = ray.d - 2.0f * dot(ray.d, it.ns) * it.ns;
      ray.o = lc_spawn_origin(it.p, it.perr, it.ng);
    } else {
      L += beta * light_point_direct(s, &it, albedo);
      *rays += P->num_lights;
      float u1 = lc_rand(pixel, sample, dim + LC_DIM_BSDF_UV, P->seed);
      float u2 = lc_rand(pixel, sample, dim + LC_DIM_BSDF_UV + 1, P->seed);
      float r = sqrt(u1), phi = 2.0f * LC_PI * u2;
      float3 t, b;
      lc_onb(it.ns, &t, &b);
      float3 wi = r * cos(phi) * t + r * sin(phi) * b + sqrt(fmax(0.0f, 1.0f - u1)) * it.ns;
      if (dot(wi, it.ng) <= 0.0f) break;
      beta *= albedo; /* cosine-weighted sampling: f cos / pdf = albedo */
      ray.o = lc_spawn_origin(it.p, it.perr, it.ng);
      ray.d = normalize(wi);
    }
    if (depth + 1 >= P->rr_depth) {
      float q = fmin(0.95f, lc_max3(beta));
      if (lc_rand(pixel, sample, dim + LC_DIM_RR, P->seed) >= q) break;
      beta /= q;
    }
  }
  return L;
}

/* First-renders integrator: direct light from point lights plus visible emission, no bounces. */
static inline float3 integrator_direct(const lc_scene* s, lc_ray ray, lc_uint* rays) {
  __global const lc_params* P = s->params;
  lc_hit hit;
  ++*rays;
  if (!scene_intersect(s, ray, INFINITY, &hit)) return lc_load3(P->env_radiance);
  lc_interaction it = interaction_from_hit(s, ray, &hit);
  __global const lc_material* m = &s->materials[it.material];
  float3 L = it.front ? lc_load3(m->emission) : (float3)(0.0f);
  *rays += P->num_lights;
  return L + light_point_direct(s, &it, material_albedo(s, m, it.uv));
}

#endif
