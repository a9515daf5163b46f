/* lucent kernel: BSDFs of every material type, in the local shading frame (z = shading normal,
 * oriented towards wo). Model: docs/rendering-model.md. Material code is compiled only for the
 * types the scene uses (LC_HAS_MIRROR, LC_HAS_DIELECTRIC, LC_HAS_CONDUCTOR, LC_HAS_PLASTIC;
 * diffuse is always present). */
#ifndef LUCENT_BSDF_BSDF_CL
#define LUCENT_BSDF_BSDF_CL

typedef struct {
  lc_uint type;
  float3 albedo;   /* diffuse colour, texture applied */
  float3 specular; /* mirror reflectance / glass tint / GGX colour */
  float ior;
  float alpha;     /* GGX alpha, clamped */
} lc_bsdf;

/* The BSDF of material m with its untextured albedo. */
static inline lc_bsdf bsdf_from_material_untextured(__global const lc_material* m) {
  lc_bsdf b;
  b.type = m->type;
  b.albedo = lc_load3(m->albedo);
  b.specular = lc_load3(m->specular);
  b.ior = m->ior;
  b.alpha = fmax(m->roughness, 1e-3f);
  return b;
}

/* The BSDF of material m at texture coordinates uv. */
static inline lc_bsdf bsdf_from_material(const lc_scene* s, __global const lc_material* m, float2 uv) {
  lc_bsdf b = bsdf_from_material_untextured(m);
#ifdef LC_HAS_TEXTURES
  if (m->albedo_tex >= 0) b.albedo = texture_lookup(s, m->albedo_tex, uv).xyz;
#endif
  return b;
}

static inline int bsdf_is_delta(const lc_bsdf* b) {
  return b->type == LC_MAT_MIRROR || b->type == LC_MAT_DIELECTRIC;
}

/* Probability of choosing the specular lobe of plastic. */
static inline float plastic_spec_prob(const lc_bsdf* b, float fo) {
  float ws = fo * lc_luminance(b->specular);
  float wd = (1.0f - fo) * lc_luminance(b->albedo);
  if (ws + wd <= 0.0f) return 0.5f;
  return clamp(ws / (ws + wd), 0.05f, 0.95f);
}

/* BSDF value (no cosine) and the solid-angle pdf with which bsdf_sample picks wi. Delta BSDFs
 * return 0. */
static inline float3 bsdf_eval(const lc_bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return (float3)(0.0f);
#if defined(LC_HAS_CONDUCTOR) || defined(LC_HAS_PLASTIC)
  if (b->type == LC_MAT_CONDUCTOR || b->type == LC_MAT_PLASTIC) {
    float3 h = normalize(wo + wi);
    float d = ggx_d(h, b->alpha);
    float g = ggx_g2(wo, wi, b->alpha);
    float pdf_spec = ggx_pdf_reflect(wo, h, b->alpha) ;
    float hw = fmax(0.0f, dot(wi, h));
    if (b->type == LC_MAT_CONDUCTOR) {
      *pdf = pdf_spec;
      return fresnel_schlick(b->specular, hw) * (d * g / (4.0f * wo.z * wi.z));
    }
    float ct;
    float fh = fresnel_dielectric(hw, b->ior, &ct);
    float fi = fresnel_dielectric(wi.z, b->ior, &ct);
    float fo = fresnel_dielectric(wo.z, b->ior, &ct);
    float ps = plastic_spec_prob(b, fo);
    *pdf = ps * pdf_spec + (1.0f - ps) * wi.z * LC_INV_PI;
    return b->specular * (fh * d * g / (4.0f * wo.z * wi.z)) +
           b->albedo * (LC_INV_PI * (1.0f - fi) * (1.0f - fo));
  }
#endif
  if (b->type != LC_MAT_DIFFUSE) return (float3)(0.0f);
  *pdf = wi.z * LC_INV_PI;
  return b->albedo * LC_INV_PI;
}

static inline float3 sample_cosine_hemisphere(float u1, float u2) {
  return (float3)(sqrt(u1) * lc_unit_circle(u2), sqrt(fmax(0.0f, 1.0f - u1)));
}

typedef struct {
  float3 wi;     /* local frame */
  float3 weight; /* f |cos| / pdf, or the delta weight */
  float pdf;     /* solid-angle pdf, 0 for delta */
  int delta;
} lc_bsdf_sample;

/* Samples wi for wo (wo.z > 0). `front` is 1 when wo is on the outside of the primitive (for
 * dielectrics). Returns 0 when no direction was produced. */
static inline int bsdf_sample(const lc_bsdf* b, float3 wo, int front, float ul, float u1, float u2,
                              lc_bsdf_sample* bs) {
  bs->delta = 0;
  bs->pdf = 0.0f;
  if (wo.z <= 0.0f) return 0;
#ifdef LC_HAS_MIRROR
  if (b->type == LC_MAT_MIRROR) {
    bs->wi = (float3)(-wo.x, -wo.y, wo.z);
    bs->weight = b->specular;
    bs->delta = 1;
    return 1;
  }
#endif
#ifdef LC_HAS_DIELECTRIC
  if (b->type == LC_MAT_DIELECTRIC) {
    float eta = front ? b->ior : 1.0f / b->ior; /* eta_t / eta_o */
    float cos_t;
    float F = fresnel_dielectric(wo.z, eta, &cos_t);
    bs->delta = 1;
    if (ul < F) {
      bs->wi = (float3)(-wo.x, -wo.y, wo.z);
      bs->weight = (float3)(1.0f);
    } else {
      bs->wi = (float3)(-wo.x / eta, -wo.y / eta, -cos_t);
      bs->weight = b->specular / (eta * eta);
    }
    return 1;
  }
#endif
#if defined(LC_HAS_CONDUCTOR) || defined(LC_HAS_PLASTIC)
  if (b->type == LC_MAT_CONDUCTOR || b->type == LC_MAT_PLASTIC) {
    int spec = 1;
    if (b->type == LC_MAT_PLASTIC) {
      float ct;
      float fo = fresnel_dielectric(wo.z, b->ior, &ct);
      spec = ul < plastic_spec_prob(b, fo);
    }
    if (spec) {
      float3 h = ggx_sample_vndf(wo, b->alpha, u1, u2);
      bs->wi = 2.0f * dot(wo, h) * h - wo;
    } else {
      bs->wi = sample_cosine_hemisphere(u1, u2);
    }
    if (bs->wi.z <= 0.0f) return 0;
    float3 f = bsdf_eval(b, wo, bs->wi, &bs->pdf);
    if (!(bs->pdf > 0.0f)) return 0;
    bs->weight = f * (bs->wi.z / bs->pdf);
    return 1;
  }
#endif
  /* diffuse: cosine-weighted, f cos / pdf = albedo */
  bs->wi = sample_cosine_hemisphere(u1, u2);
  bs->pdf = bs->wi.z * LC_INV_PI;
  bs->weight = b->albedo;
  return bs->pdf > 0.0f;
}

/* The albedo AOV of a material (docs/rendering-model.md). */
static inline float3 bsdf_albedo_aov(const lc_bsdf* b) {
  if (b->type == LC_MAT_DIFFUSE || b->type == LC_MAT_PLASTIC) return b->albedo;
  return b->specular;
}

#endif
