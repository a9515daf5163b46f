/* lucent kernel: the diffuse (Lambertian) BSDF: f = albedo / pi, sampled by the cosine.
 * Parameters (lc_diffuse_params): albedo, or the texture albedo_tex when >= 0. */
#ifndef LUCENT_BSDF_DIFFUSE_CL
#define LUCENT_BSDF_DIFFUSE_CL

static inline void bsdf_diffuse_setup(lc_bsdf* b, const lc_scene* s, float2 uv) {
#ifdef LC_HAS_TEXTURES
  if (b->p.diffuse.albedo_tex >= 0)
    lc_store3p(b->p.diffuse.albedo, texture_lookup(s, b->p.diffuse.albedo_tex, uv).xyz);
#endif
}

static inline float3 bsdf_diffuse_eval(const lc_bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return (float3)(0.0f);
  *pdf = wi.z * LC_INV_PI;
  return lc_load3p(b->p.diffuse.albedo) * LC_INV_PI;
}

/* cosine-weighted: f cos / pdf = albedo */
static inline int bsdf_diffuse_sample(const lc_bsdf* b, float3 wo, float ul, float u1, float u2,
                                      lc_bsdf_sample* bs) {
  bs->wi = sample_cosine_hemisphere(u1, u2);
  bs->pdf = bs->wi.z * LC_INV_PI;
  bs->weight = lc_load3p(b->p.diffuse.albedo);
  return bs->pdf > 0.0f;
}

static inline float3 bsdf_diffuse_albedo(const lc_bsdf* b) {
  return lc_load3p(b->p.diffuse.albedo);
}

static inline lc_uint bsdf_diffuse_lobes(const lc_bsdf* b) { return 0u; }

static inline void bsdf_diffuse_whitted(const lc_bsdf* b, float3 wo, lc_whitted_bsdf* w) {
  w->diffuse_lobe = 1;
  w->diffuse = lc_load3p(b->p.diffuse.albedo);
}

#endif
