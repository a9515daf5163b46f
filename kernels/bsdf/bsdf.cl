/* lucent kernel: the BSDF interface and its dispatch. Each material type of shared/registry.h
 * (LC_MATERIAL_TYPES) has its file bsdf/<file>.cl, which defines, in the local shading frame
 * (z = shading normal, oriented towards wo, so wo.z > 0):
 *   void   bsdf_<file>_setup(lc_bsdf* b, const lc_scene* s, float2 uv)
 *            at a hit: texture lookups into the closure's own copy of the parameters
 *   float3 bsdf_<file>_eval(const lc_bsdf* b, float3 wo, float3 wi, float* pdf)
 *            the BSDF value f (no cosine) and the solid-angle pdf with which _sample picks wi;
 *            0 and 0 for delta BSDFs
 *   int    bsdf_<file>_sample(const lc_bsdf* b, float3 wo, float ul, float u1, float u2,
 *                             lc_bsdf_sample* bs)
 *            draws wi from numbers in [0, 1) (ul chooses a lobe); 0 when no direction was made
 *   float3 bsdf_<file>_albedo(const lc_bsdf* b)      the albedo AOV
 *   lc_uint bsdf_<file>_lobes(const lc_bsdf* b)      LC_BSDF_* flags
 *   void   bsdf_<file>_whitted(const lc_bsdf* b, float3 wo, lc_whitted_bsdf* w)
 *            the deterministic split the Whitted integrator uses
 * Every type's file is included (generated/materials.cl lists them from the registry); the
 * dispatch below compiles a type's branch only when its feature define is set (LC_ENABLED). The
 * mathematics of each type is in docs/rendering-model.md. */
#ifndef LUCENT_BSDF_BSDF_CL
#define LUCENT_BSDF_BSDF_CL

/* lc_bsdf_lobes flags */
#define LC_BSDF_DELTA 1u        /* only delta lobes: no light sampling, no MIS weights       */
#define LC_BSDF_TRANSMISSION 2u /* scatters through the surface as well (light on both sides) */

/* A material at a hit, ready for evaluation: its type and a private copy of its parameters,
 * textures applied. */
typedef struct {
  lc_uint type;         /* LC_MAT_*                                               */
  int front;            /* 1 when wo is on the outside of the primitive            */
  lc_material_params p; /* p.<file>: the type's parameters (shared/registry.h)     */
} lc_bsdf;

typedef struct {
  float3 wi;     /* local frame */
  float3 weight; /* f |cos| / pdf, or the delta weight */
  float pdf;     /* solid-angle pdf, 0 for delta */
  int delta;
  float eta;  /* refraction: eta_t / eta_o (weight has its 1 / eta^2); 1 otherwise */
  float prob; /* the probability of choosing this lobe among the BSDF's delta lobes (smooth glass:
               * F or 1 - F; the weight has its 1 / prob); 1 for the other BSDFs */
} lc_bsdf_sample;

/* What the Whitted integrator (integrator/whitted.cl) takes of a BSDF: a lambertian part lit by
 * point lights, a mirror reflection about the shading normal and a refraction, each with a
 * deterministic weight. */
typedef struct {
  int diffuse_lobe;   /* point lights light this BSDF through diffuse / pi */
  float3 diffuse;     /* lambertian albedo                                  */
  float3 reflect;     /* weight of the mirror reflection (0: none)          */
  float3 transmit;    /* weight of the refraction (0: none)                 */
  float3 transmit_wi; /* refracted direction, local frame                   */
} lc_whitted_bsdf;

/* Private float triples of a parameter struct. */
static inline float3 lc_load3p(const float* p) { return (float3)(p[0], p[1], p[2]); }
static inline void lc_store3p(float* p, float3 v) {
  p[0] = v.x;
  p[1] = v.y;
  p[2] = v.z;
}

static inline void whitted_bsdf_none(lc_whitted_bsdf* w) {
  w->diffuse_lobe = 0;
  w->diffuse = w->reflect = w->transmit = w->transmit_wi = (float3)(0.0f);
}

/* Whitted's classic weights of a dielectric interface of relative index eta (eta_t / eta_i, wo
 * on the incident side): reflection F, refraction (1 - F) tint (no 1 / eta^2). */
static inline void whitted_dielectric(float3 wo, float eta, float3 tint, lc_whitted_bsdf* w) {
  float ct;
  float F = fresnel_dielectric(wo.z, eta, &ct);
  w->reflect = (float3)(F);
  if (F < 1.0f) {
    w->transmit = tint * (1.0f - F);
    w->transmit_wi = (float3)(-wo.x / eta, -wo.y / eta, -ct);
  }
}

/* bsdf/<file>.cl for every material type */
#include "generated/materials.cl"

/* ---- dispatch ---- */

/* The BSDF of material m with its untextured parameters, seen from the outside. */
static inline lc_bsdf bsdf_from_material_untextured(__global const lc_material* m) {
  lc_bsdf b;
  b.type = m->type;
  b.front = 1;
  b.p = m->p;
  return b;
}

#define LC_BSDF_SETUP(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && b.type == LC_MAT_##ID) bsdf_##file##_setup(&b, s, uv);
/* The BSDF of material m at texture coordinates uv, for a ray that hit the front side or not. */
static inline lc_bsdf bsdf_from_material(const lc_scene* s, __global const lc_material* m,
                                         float2 uv, int front) {
  lc_bsdf b = bsdf_from_material_untextured(m);
  b.front = front;
  LC_MATERIAL_TYPES(LC_BSDF_SETUP)
  return b;
}
#undef LC_BSDF_SETUP

#define LC_BSDF_EVAL(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && b->type == LC_MAT_##ID) return bsdf_##file##_eval(b, wo, wi, pdf);
/* BSDF value (no cosine) and the solid-angle pdf with which bsdf_sample picks wi. */
static inline float3 bsdf_eval(const lc_bsdf* b, float3 wo, float3 wi, float* pdf) {
  LC_MATERIAL_TYPES(LC_BSDF_EVAL)
  *pdf = 0.0f;
  return (float3)(0.0f);
}
#undef LC_BSDF_EVAL

/* The solid-angle pdf with which bsdf_sample picks wi. */
static inline float bsdf_pdf(const lc_bsdf* b, float3 wo, float3 wi) {
  float pdf;
  bsdf_eval(b, wo, wi, &pdf);
  return pdf;
}

#define LC_BSDF_SAMPLE(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && b->type == LC_MAT_##ID)                 \
    return bsdf_##file##_sample(b, wo, ul, u1, u2, bs);
/* Samples wi for wo (wo.z > 0). Returns 0 when no direction was produced. */
static inline int bsdf_sample(const lc_bsdf* b, float3 wo, float ul, float u1, float u2,
                              lc_bsdf_sample* bs) {
  bs->delta = 0;
  bs->pdf = 0.0f;
  bs->eta = 1.0f;
  bs->prob = 1.0f;
  if (wo.z <= 0.0f) return 0;
  LC_MATERIAL_TYPES(LC_BSDF_SAMPLE)
  return 0;
}
#undef LC_BSDF_SAMPLE

#define LC_BSDF_ALBEDO(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && b->type == LC_MAT_##ID) return bsdf_##file##_albedo(b);
/* The albedo AOV of a material (docs/rendering-model.md). */
static inline float3 bsdf_albedo_aov(const lc_bsdf* b) {
  LC_MATERIAL_TYPES(LC_BSDF_ALBEDO)
  return (float3)(0.0f);
}
#undef LC_BSDF_ALBEDO

#define LC_BSDF_LOBES(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && b->type == LC_MAT_##ID) return bsdf_##file##_lobes(b);
static inline lc_uint bsdf_lobes(const lc_bsdf* b) {
  LC_MATERIAL_TYPES(LC_BSDF_LOBES)
  return 0u;
}
#undef LC_BSDF_LOBES

static inline int bsdf_is_delta(const lc_bsdf* b) { return (bsdf_lobes(b) & LC_BSDF_DELTA) != 0; }

#define LC_BSDF_WHITTED(ID, Name, value, name, feature, file, params) \
  if (LC_ENABLED(feature) && b->type == LC_MAT_##ID) {                \
    bsdf_##file##_whitted(b, wo, &w);                                 \
    return w;                                                         \
  }
/* The Whitted integrator's view of the BSDF for wo (wo.z > 0). */
static inline lc_whitted_bsdf bsdf_whitted(const lc_bsdf* b, float3 wo) {
  lc_whitted_bsdf w;
  whitted_bsdf_none(&w);
  LC_MATERIAL_TYPES(LC_BSDF_WHITTED)
  return w;
}
#undef LC_BSDF_WHITTED

#endif
