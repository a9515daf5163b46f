/* lucent kernel: the rough dielectric: GGX microfacet reflection and transmission (Walter,
 * Marschner, Li and Torrance 2007, "Microfacet Models for Refraction through Rough Surfaces"),
 * the exact dielectric Fresnel term at the microfacet normal, height-correlated Smith G2. Sampled
 * by visible normals (bsdf/microfacet.cl), then reflection with probability F(wo.h) and refraction
 * otherwise. Radiance transport: the transmitted term is divided by eta^2 and multiplied by tint,
 * as the smooth dielectric's refraction weight tint / eta^2. Two-sided: eta = ior from the outside,
 * 1 / ior from the inside. An ior of 1 is no interface: light passes straight through, weighted
 * by tint (a delta BSDF; the generalized half vector of refraction does not exist there). The
 * host packs an ior within 1e-5 of 1 as 1 (src/scene/materials/rough_dielectric.cpp).
 * Parameters (lc_rough_dielectric_params): tint, ior, roughness (GGX alpha, at least 1e-3). */
#ifndef LUCENT_BSDF_ROUGH_DIELECTRIC_CL
#define LUCENT_BSDF_ROUGH_DIELECTRIC_CL

static inline void bsdf_rough_dielectric_setup(lc_bsdf* b, const lc_scene* s, float2 uv) {}

static inline float bsdf_rough_dielectric_alpha(const lc_bsdf* b) {
  return fmax(b->p.rough_dielectric.roughness, 1e-3f);
}

/* eta_t / eta_o for the side wo is on */
static inline float bsdf_rough_dielectric_eta(const lc_bsdf* b) {
  return b->front ? b->p.rough_dielectric.ior : 1.0f / b->p.rough_dielectric.ior;
}

static inline float3 bsdf_rough_dielectric_eval(const lc_bsdf* b, float3 wo, float3 wi,
                                                float* pdf) {
  *pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z == 0.0f || b->p.rough_dielectric.ior == 1.0f) return (float3)(0.0f);
  float alpha = bsdf_rough_dielectric_alpha(b), eta = bsdf_rough_dielectric_eta(b);
  int reflect = wi.z > 0.0f;
  /* the microfacet normal: the half vector, or the generalized one of refraction, facing +z */
  float3 h = reflect ? wo + wi : wo + eta * wi;
  float hl = length(h);
  if (!(hl > 0.0f)) return (float3)(0.0f);
  h /= hl;
  if (h.z < 0.0f) h = -h;
  float oh = dot(wo, h), ih = dot(wi, h);
  /* microfacets seen from behind by either direction contribute nothing */
  if (oh <= 0.0f || (reflect ? ih <= 0.0f : ih >= 0.0f)) return (float3)(0.0f);
  float ct;
  float F = fresnel_dielectric(oh, eta, &ct);
  float d = ggx_d(h, alpha);
  float g = ggx_g2(wo, (float3)(wi.x, wi.y, fabs(wi.z)), alpha);
  /* density of the visible normal h, G1(wo) D(h) (wo.h) / wo.z */
  float dv = ggx_g1(wo, alpha) * d * oh / wo.z;
  if (reflect) {
    *pdf = F * dv / (4.0f * oh);
    return (float3)(F * d * g / (4.0f * wo.z * wi.z));
  }
  /* refraction: dwh / dwi = eta^2 |wi.h| / (wo.h + eta wi.h)^2 (Walter et al. eq. 17) */
  float denom = oh + eta * ih;
  denom *= denom;
  *pdf = (1.0f - F) * dv * eta * eta * fabs(ih) / denom;
  float ft = (1.0f - F) * d * g * fabs(ih) * oh / (wo.z * fabs(wi.z) * denom);
  /* eta^2 of the change of measure cancels the 1 / eta^2 of radiance transport */
  return lc_load3p(b->p.rough_dielectric.tint) * ft;
}

static inline int bsdf_rough_dielectric_sample(const lc_bsdf* b, float3 wo, float ul, float u1,
                                               float u2, lc_bsdf_sample* bs) {
  float eta = bsdf_rough_dielectric_eta(b);
  if (eta == 1.0f) { /* no interface */
    bs->wi = -wo;
    bs->weight = lc_load3p(b->p.rough_dielectric.tint);
    bs->delta = 1;
    return 1;
  }
  float3 h = ggx_sample_vndf(wo, bsdf_rough_dielectric_alpha(b), u1, u2);
  float oh = dot(wo, h);
  if (!(oh > 0.0f)) return 0;
  float cos_t;
  float F = fresnel_dielectric(oh, eta, &cos_t);
  if (ul < F) {
    bs->wi = 2.0f * oh * h - wo;
    if (bs->wi.z <= 0.0f) return 0;
  } else {
    bs->wi = normalize((oh / eta - cos_t) * h - wo / eta);
    if (bs->wi.z >= 0.0f) return 0;
    bs->eta = eta;
  }
  float3 f = bsdf_rough_dielectric_eval(b, wo, bs->wi, &bs->pdf);
  if (!(bs->pdf > 0.0f)) return 0;
  bs->weight = f * (fabs(bs->wi.z) / bs->pdf);
  return 1;
}

static inline float3 bsdf_rough_dielectric_albedo(const lc_bsdf* b) {
  return lc_load3p(b->p.rough_dielectric.tint);
}

static inline lc_uint bsdf_rough_dielectric_lobes(const lc_bsdf* b) { return LC_BSDF_TRANSMISSION; }

/* as the smooth dielectric: reflection F, refraction (1 - F) tint about the shading normal */
static inline void bsdf_rough_dielectric_whitted(const lc_bsdf* b, float3 wo, lc_whitted_bsdf* w) {
  whitted_dielectric(wo, bsdf_rough_dielectric_eta(b), lc_load3p(b->p.rough_dielectric.tint), w);
}

#endif
