/* lucent kernel: the smooth dielectric (glass): delta reflection with the exact Fresnel term F and
 * delta refraction with 1 - F, the transmitted radiance scaled by tint / eta^2 (radiance
 * transport). Parameters (lc_dielectric_params): tint, ior (outside to inside). */
#ifndef LUCENT_BSDF_DIELECTRIC_CL
#define LUCENT_BSDF_DIELECTRIC_CL

static inline void bsdf_dielectric_setup(lc_bsdf* b, const lc_scene* s, float2 uv) {}

static inline float3 bsdf_dielectric_eval(const lc_bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  return (float3)(0.0f);
}

/* eta_t / eta_o for the side wo is on */
static inline float bsdf_dielectric_eta(const lc_bsdf* b) {
  return b->front ? b->p.dielectric.ior : 1.0f / b->p.dielectric.ior;
}

static inline int bsdf_dielectric_sample(const lc_bsdf* b, float3 wo, float ul, float u1, float u2,
                                         lc_bsdf_sample* bs) {
  float eta = bsdf_dielectric_eta(b);
  float cos_t;
  float F = fresnel_dielectric(wo.z, eta, &cos_t);
  bs->delta = 1;
  if (ul < F) {
    bs->wi = (float3)(-wo.x, -wo.y, wo.z);
    bs->weight = (float3)(1.0f);
    bs->prob = F;
  } else {
    bs->wi = (float3)(-wo.x / eta, -wo.y / eta, -cos_t);
    bs->weight = lc_load3p(b->p.dielectric.tint) / (eta * eta);
    bs->eta = eta;
    bs->prob = 1.0f - F;
  }
  return 1;
}

static inline float3 bsdf_dielectric_albedo(const lc_bsdf* b) {
  return lc_load3p(b->p.dielectric.tint);
}

static inline lc_uint bsdf_dielectric_lobes(const lc_bsdf* b) {
  return LC_BSDF_DELTA | LC_BSDF_TRANSMISSION;
}

/* reflection F, refraction (1 - F) tint (no 1 / eta^2: Whitted's classic weights) */
static inline void bsdf_dielectric_whitted(const lc_bsdf* b, float3 wo, lc_whitted_bsdf* w) {
  whitted_dielectric(wo, bsdf_dielectric_eta(b), lc_load3p(b->p.dielectric.tint), w);
}

#endif
