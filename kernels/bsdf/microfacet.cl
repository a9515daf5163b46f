/* lucent kernel: GGX (Trowbridge-Reitz) microfacet distribution in the local frame (z = normal):
 * D, height-correlated Smith masking-shadowing, and sampling of the visible normals
 * (Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 2018). */
#ifndef LUCENT_BSDF_MICROFACET_CL
#define LUCENT_BSDF_MICROFACET_CL

/* h a unit vector. t = cos^2 (a2 + tan^2) = sin^2 + a2 cos^2, with sin^2 from h's tangential
 * components: as 1 - cos^2 (c2 (a2 - 1) + 1) it cancelled near the peak, where sin^2 is of the
 * order of a2, and at alpha = 1e-3 (roughness 0) D came out up to 44% off next to the mirror
 * direction (a float cos^2 near 1 resolves sin^2 to 6e-8 only; tests/test_kernel_bsdf.cpp,
 * GgxEvalMatchesReferenceAtSmallRoughness). */
static inline float ggx_d(float3 h, float alpha) {
  float c2 = h.z * h.z;
  if (c2 <= 0.0f) return 0.0f;
  float a2 = alpha * alpha;
  float t = (h.x * h.x + h.y * h.y) + a2 * c2;
  return a2 / (LC_PI * t * t);
}

static inline float ggx_lambda(float3 w, float alpha) {
  float c2 = w.z * w.z;
  if (c2 <= 0.0f) return INFINITY;
  float t2 = fmax(0.0f, 1.0f - c2) / c2;
  return 0.5f * (-1.0f + sqrt(1.0f + alpha * alpha * t2));
}

static inline float ggx_g1(float3 w, float alpha) { return 1.0f / (1.0f + ggx_lambda(w, alpha)); }

static inline float ggx_g2(float3 wo, float3 wi, float alpha) {
  return 1.0f / (1.0f + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
}

/* A visible normal for wo (wo.z > 0). */
static inline float3 ggx_sample_vndf(float3 wo, float alpha, float u1, float u2) {
  float3 vh = normalize((float3)(alpha * wo.x, alpha * wo.y, wo.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  float3 t1 = lensq > 0.0f ? (float3)(-vh.y, vh.x, 0.0f) / sqrt(lensq) : (float3)(1.0f, 0.0f, 0.0f);
  float3 t2 = cross(vh, t1);
  float2 p = sqrt(u1) * lc_unit_circle(u2);
  float p1 = p.x, p2 = p.y;
  float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * sqrt(fmax(0.0f, 1.0f - p1 * p1)) + s * p2;
  float3 nh = p1 * t1 + p2 * t2 + sqrt(fmax(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return normalize((float3)(alpha * nh.x, alpha * nh.y, fmax(1e-6f, nh.z)));
}

/* Solid-angle pdf of the reflected direction when h is sampled by ggx_sample_vndf. */
static inline float ggx_pdf_reflect(float3 wo, float3 h, float alpha) {
  if (wo.z <= 0.0f) return 0.0f;
  return ggx_g1(wo, alpha) * ggx_d(h, alpha) / (4.0f * wo.z);
}

#endif
