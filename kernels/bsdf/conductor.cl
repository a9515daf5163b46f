/* lucent kernel: the rough conductor: GGX microfacet reflection (height-correlated Smith
 * masking-shadowing, bsdf/microfacet.cl) with Schlick's Fresnel from the F0 colour, sampled by
 * visible normals. Parameters (lc_conductor_params): f0, roughness (GGX alpha, at least 1e-3). */
#ifndef LUCENT_BSDF_CONDUCTOR_CL
#define LUCENT_BSDF_CONDUCTOR_CL

static inline void bsdf_conductor_setup(lc_bsdf* b, const lc_scene* s, float2 uv) {}

static inline float bsdf_conductor_alpha(const lc_bsdf* b) {
  return fmax(b->p.conductor.roughness, 1e-3f);
}

static inline float3 bsdf_conductor_eval(const lc_bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return (float3)(0.0f);
  float alpha = bsdf_conductor_alpha(b);
  float3 h = normalize(wo + wi);
  float d = ggx_d(h, alpha);
  float g = ggx_g2(wo, wi, alpha);
  float hw = fmax(0.0f, dot(wi, h));
  *pdf = ggx_pdf_reflect(wo, h, alpha);
  return fresnel_schlick(lc_load3p(b->p.conductor.f0), hw) * (d * g / (4.0f * wo.z * wi.z));
}

static inline int bsdf_conductor_sample(const lc_bsdf* b, float3 wo, float ul, float u1, float u2,
                                        lc_bsdf_sample* bs) {
  float3 h = ggx_sample_vndf(wo, bsdf_conductor_alpha(b), u1, u2);
  bs->wi = 2.0f * dot(wo, h) * h - wo;
  if (bs->wi.z <= 0.0f) return 0;
  float3 f = bsdf_conductor_eval(b, wo, bs->wi, &bs->pdf);
  if (!(bs->pdf > 0.0f)) return 0;
  bs->weight = f * (bs->wi.z / bs->pdf);
  return 1;
}

static inline float3 bsdf_conductor_albedo(const lc_bsdf* b) {
  return lc_load3p(b->p.conductor.f0);
}

static inline lc_uint bsdf_conductor_lobes(const lc_bsdf* b) { return 0u; }

/* a mirror with the F0 colour */
static inline void bsdf_conductor_whitted(const lc_bsdf* b, float3 wo, lc_whitted_bsdf* w) {
  w->reflect = lc_load3p(b->p.conductor.f0);
}

#endif
