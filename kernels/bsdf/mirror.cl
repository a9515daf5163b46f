/* lucent kernel: the perfect mirror: delta reflection about the shading normal with an RGB
 * reflectance (lc_mirror_params). */
#ifndef LUCENT_BSDF_MIRROR_CL
#define LUCENT_BSDF_MIRROR_CL

static inline void bsdf_mirror_setup(lc_bsdf* b, const lc_scene* s, float2 uv) {}

static inline float3 bsdf_mirror_eval(const lc_bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  return (float3)(0.0f);
}

static inline int bsdf_mirror_sample(const lc_bsdf* b, float3 wo, float ul, float u1, float u2,
                                     lc_bsdf_sample* bs) {
  bs->wi = (float3)(-wo.x, -wo.y, wo.z);
  bs->weight = lc_load3p(b->p.mirror.reflectance);
  bs->delta = 1;
  return 1;
}

static inline float3 bsdf_mirror_albedo(const lc_bsdf* b) {
  return lc_load3p(b->p.mirror.reflectance);
}

static inline lc_uint bsdf_mirror_lobes(const lc_bsdf* b) { return LC_BSDF_DELTA; }

static inline void bsdf_mirror_whitted(const lc_bsdf* b, float3 wo, lc_whitted_bsdf* w) {
  w->reflect = lc_load3p(b->p.mirror.reflectance);
}

#endif
