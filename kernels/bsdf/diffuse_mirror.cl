/* lucent kernel: diffuse_mirror: Whitted's k_d + k_s surface, a Lambertian base plus a perfect
 * mirror with a constant RGB weight (no Fresnel term): f = albedo / pi + reflectance * delta(wi -
 * mirror(wo)) / cos. One lobe is chosen per sample, the mirror with probability
 * pm = sum(reflectance) / (sum(reflectance) + sum(albedo)) (channel sums), the cosine-distributed
 * diffuse lobe otherwise; eval returns the diffuse part only, with the pdf (1 - pm) cos / pi with
 * which _sample picks a diffuse direction, so that next-event estimation lights the diffuse part
 * and MIS weighs it. The BSDF is not wholly delta (lobes 0): the path integrator samples lights
 * at it, and a sampled mirror direction is a delta sample (bs->delta, no MIS on what it hits).
 * Parameters (lc_diffuse_mirror_params): albedo, or the texture albedo_tex when >= 0, and
 * reflectance. */
#ifndef LUCENT_BSDF_DIFFUSE_MIRROR_CL
#define LUCENT_BSDF_DIFFUSE_MIRROR_CL

static inline void bsdf_diffuse_mirror_setup(lc_bsdf* b, const lc_scene* s, float2 uv) {
#ifdef LC_HAS_TEXTURES
  if (b->p.diffuse_mirror.albedo_tex >= 0)
    lc_store3p(b->p.diffuse_mirror.albedo,
               texture_lookup(s, b->p.diffuse_mirror.albedo_tex, uv).xyz);
#endif
}

/* The probability of sampling the mirror lobe: its share of the channel sums (0 without a
 * mirror, 1 without a diffuse part). */
static inline float diffuse_mirror_prob(const lc_bsdf* b) {
  float3 a = lc_load3p(b->p.diffuse_mirror.albedo);
  float3 r = lc_load3p(b->p.diffuse_mirror.reflectance);
  float sr = r.x + r.y + r.z, sa = a.x + a.y + a.z;
  return sr > 0.0f ? sr / (sr + sa) : 0.0f;
}

static inline float3 bsdf_diffuse_mirror_eval(const lc_bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return (float3)(0.0f);
  *pdf = (1.0f - diffuse_mirror_prob(b)) * wi.z * LC_INV_PI;
  return lc_load3p(b->p.diffuse_mirror.albedo) * LC_INV_PI;
}

static inline int bsdf_diffuse_mirror_sample(const lc_bsdf* b, float3 wo, float ul, float u1,
                                             float u2, lc_bsdf_sample* bs) {
  float pm = diffuse_mirror_prob(b);
  if (ul < pm) {
    bs->wi = (float3)(-wo.x, -wo.y, wo.z);
    bs->weight = lc_load3p(b->p.diffuse_mirror.reflectance) / pm;
    bs->pdf = 0.0f;
    bs->delta = 1;
    return 1;
  }
  bs->wi = sample_cosine_hemisphere(u1, u2);
  bs->pdf = (1.0f - pm) * bs->wi.z * LC_INV_PI;
  if (!(bs->pdf > 0.0f)) return 0;
  bs->weight = lc_load3p(b->p.diffuse_mirror.albedo) / (1.0f - pm);
  return 1;
}

/* the directional albedo, diffuse plus mirror (diffuse's albedo without a mirror, mirror's
 * reflectance without a diffuse part) */
static inline float3 bsdf_diffuse_mirror_albedo(const lc_bsdf* b) {
  return lc_load3p(b->p.diffuse_mirror.albedo) + lc_load3p(b->p.diffuse_mirror.reflectance);
}

static inline lc_uint bsdf_diffuse_mirror_lobes(const lc_bsdf* b) { return 0u; }

/* the tutorial's model: the diffuse part lit by point lights, plus reflectance x the mirror ray */
static inline void bsdf_diffuse_mirror_whitted(const lc_bsdf* b, float3 wo, lc_whitted_bsdf* w) {
  w->diffuse_lobe = 1;
  w->diffuse = lc_load3p(b->p.diffuse_mirror.albedo);
  w->reflect = lc_load3p(b->p.diffuse_mirror.reflectance);
}

#endif
