/* lucent kernel: arbitrary output variables of the first hit. Each AOV of shared/registry.h
 * (LC_AOV_TYPES) is a function here,
 *   float3 aov_<file>(const lc_scene* s, lc_ray ray, const lc_rng* rng, const lc_hit* hit,
 *                     const lc_interaction* it, lc_uint* rays),
 * and integrator_aov traces the camera ray and dispatches on lc_params.integrator. A miss gives 0
 * for every AOV. */
#ifndef LUCENT_INTEGRATOR_AOV_CL
#define LUCENT_INTEGRATOR_AOV_CL

/* distance along the camera ray */
static inline float3 aov_depth(const lc_scene* s, lc_ray ray, const lc_rng* rng, const lc_hit* hit,
                               const lc_interaction* it, lc_uint* rays) {
  return (float3)((float)hit->t);
}

/* 1 + the primitive's index in scene order: spheres first, then the scene's triangle list (exact
 * in float below 2^24) */
static inline float3 aov_primitive(const lc_scene* s, lc_ray ray, const lc_rng* rng,
                                   const lc_hit* hit, const lc_interaction* it, lc_uint* rays) {
  lc_uint id = (hit->prim & LC_PRIM_SPHERE_BIT)
                   ? (hit->prim & ~LC_PRIM_SPHERE_BIT)
                   : s->params->num_spheres + s->tri_attrs[hit->prim].source_index;
  return (float3)((float)(id + 1u));
}

/* the shading normal, facing the camera */
static inline float3 aov_normal(const lc_scene* s, lc_ray ray, const lc_rng* rng, const lc_hit* hit,
                                const lc_interaction* it, lc_uint* rays) {
  return it->ns;
}

/* the material's albedo AOV (bsdf_albedo_aov) */
static inline float3 aov_albedo(const lc_scene* s, lc_ray ray, const lc_rng* rng, const lc_hit* hit,
                                const lc_interaction* it, lc_uint* rays) {
  lc_bsdf b = bsdf_from_material(s, &s->materials[it->material], it->uv, it->front);
  return bsdf_albedo_aov(&b);
}

/* ambient occlusion: 1 when a cosine-distributed ray reaches ao_distance unoccluded */
static inline float3 aov_ao(const lc_scene* s, lc_ray ray, const lc_rng* rng, const lc_hit* hit,
                            const lc_interaction* it, lc_uint* rays) {
  lc_frame fr = frame_from(it->ns);
  float2 u = lc_rand2(rng, LC_DIM_BOUNCE + LC_DIM_BSDF_UV);
  lc_real3 wi = frame_to_world_dir(&fr, sample_cosine_hemisphere(u.x, u.y));
  if (dot(wi, it->ng) <= LC_REAL(0.0)) return (float3)(0.0f);
  lc_ray sr;
  sr.o = lc_spawn_origin(it->p, it->perr, it->ng);
  sr.d = wi;
  ++*rays;
  return scene_occluded(s, sr, s->params->ao_distance) ? (float3)(0.0f) : (float3)(1.0f);
}

#define LC_AOV_CALL(ID, Name, value, name, feature, file) \
  if (P->integrator == LC_INTEGRATOR_##ID) return aov_##file(s, ray, rng, &hit, &it, rays);
static inline float3 integrator_aov(const lc_scene* s, lc_ray ray, const lc_rng* rng,
                                    lc_uint* rays) {
  __global const lc_params* P = s->params;
  lc_hit hit;
  ++*rays;
  if (!scene_intersect(s, ray, INFINITY, &hit)) return (float3)(0.0f);
  lc_interaction it = interaction_from_hit(s, ray, &hit);
  LC_AOV_TYPES(LC_AOV_CALL)
  return (float3)(0.0f);
}
#undef LC_AOV_CALL

#endif
