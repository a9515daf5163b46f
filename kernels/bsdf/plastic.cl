/* lucent kernel: plastic: a GGX dielectric coating (exact Fresnel at the half vector, specular
 * colour) over a diffuse base seen through the coating's Fresnel transmission at both directions.
 * Sampled by choosing the coating (visible normals) or the base (cosine) in proportion to their
 * Fresnel-weighted luminance, clamped to [0.05, 0.95]. Parameters (lc_plastic_params): albedo or
 * albedo_tex, specular, ior, roughness (GGX alpha, at least 1e-3). */
#ifndef LUCENT_BSDF_PLASTIC_CL
#define LUCENT_BSDF_PLASTIC_CL

static inline void bsdf_plastic_setup(lc_bsdf* b, const lc_scene* s, float2 uv) {
#ifdef LC_HAS_TEXTURES
  if (b->p.plastic.albedo_tex >= 0)
    lc_store3p(b->p.plastic.albedo, texture_lookup(s, b->p.plastic.albedo_tex, uv).xyz);
#endif
}

static inline float bsdf_plastic_alpha(const lc_bsdf* b) {
  return fmax(b->p.plastic.roughness, 1e-3f);
}

/* Probability of choosing the specular lobe, given the Fresnel reflectance fo at wo. */
static inline float plastic_spec_prob(const lc_bsdf* b, float fo) {
  float ws = fo * lc_luminance(lc_load3p(b->p.plastic.specular));
  float wd = (1.0f - fo) * lc_luminance(lc_load3p(b->p.plastic.albedo));
  if (ws + wd <= 0.0f) return 0.5f;
  return clamp(ws / (ws + wd), 0.05f, 0.95f);
}

static inline float3 bsdf_plastic_eval(const lc_bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return (float3)(0.0f);
  float alpha = bsdf_plastic_alpha(b), ior = b->p.plastic.ior;
  float3 h = normalize(wo + wi);
  float d = ggx_d(h, alpha);
  float g = ggx_g2(wo, wi, alpha);
  float pdf_spec = ggx_pdf_reflect(wo, h, alpha);
  float hw = fmax(0.0f, dot(wi, h));
  float ct;
  float fh = fresnel_dielectric(hw, ior, &ct);
  float fi = fresnel_dielectric(wi.z, ior, &ct);
  float fo = fresnel_dielectric(wo.z, ior, &ct);
  float ps = plastic_spec_prob(b, fo);
  *pdf = ps * pdf_spec + (1.0f - ps) * wi.z * LC_INV_PI;
  return lc_load3p(b->p.plastic.specular) * (fh * d * g / (4.0f * wo.z * wi.z)) +
         lc_load3p(b->p.plastic.albedo) * (LC_INV_PI * (1.0f - fi) * (1.0f - fo));
}

static inline int bsdf_plastic_sample(const lc_bsdf* b, float3 wo, float ul, float u1, float u2,
                                      lc_bsdf_sample* bs) {
  float ct;
  float fo = fresnel_dielectric(wo.z, b->p.plastic.ior, &ct);
  if (ul < plastic_spec_prob(b, fo)) {
    float3 h = ggx_sample_vndf(wo, bsdf_plastic_alpha(b), u1, u2);
    bs->wi = 2.0f * dot(wo, h) * h - wo;
  } else {
    bs->wi = sample_cosine_hemisphere(u1, u2);
  }
  if (bs->wi.z <= 0.0f) return 0;
  float3 f = bsdf_plastic_eval(b, wo, bs->wi, &bs->pdf);
  if (!(bs->pdf > 0.0f)) return 0;
  bs->weight = f * (bs->wi.z / bs->pdf);
  return 1;
}

static inline float3 bsdf_plastic_albedo(const lc_bsdf* b) {
  return lc_load3p(b->p.plastic.albedo);
}

static inline lc_uint bsdf_plastic_lobes(const lc_bsdf* b) { return 0u; }

/* the base lit by point lights through albedo / pi, the coating as a mirror of weight F specular */
static inline void bsdf_plastic_whitted(const lc_bsdf* b, float3 wo, lc_whitted_bsdf* w) {
  float ct;
  w->diffuse_lobe = 1;
  w->diffuse = lc_load3p(b->p.plastic.albedo);
  w->reflect = lc_load3p(b->p.plastic.specular) * fresnel_dielectric(wo.z, b->p.plastic.ior, &ct);
}

#endif
