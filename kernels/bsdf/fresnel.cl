/* lucent kernel: Fresnel terms. */
#ifndef LUCENT_BSDF_FRESNEL_CL
#define LUCENT_BSDF_FRESNEL_CL

/* Unpolarized Fresnel reflectance of a dielectric interface. cos_i is the cosine on the incident
 * side (> 0), eta = eta_t / eta_i. Returns 1 for total internal reflection; writes the cosine of
 * the refracted direction (> 0) to cos_t. */
static inline float fresnel_dielectric(float cos_i, float eta, float* cos_t) {
  cos_i = clamp(cos_i, 0.0f, 1.0f);
  /* cos_t = sqrt(1 - (1 - cos_i^2) / eta^2), written so that eta = 1 gives cos_t = cos_i exactly */
  float k = eta * eta - 1.0f + cos_i * cos_i;
  if (k <= 0.0f) {
    *cos_t = 0.0f;
    return 1.0f;
  }
  float ct = sqrt(k) / eta;
  *cos_t = ct;
  float rs = (cos_i - eta * ct) / (cos_i + eta * ct);
  float rp = (eta * cos_i - ct) / (eta * cos_i + ct);
  return 0.5f * (rs * rs + rp * rp);
}

static inline float3 fresnel_schlick(float3 f0, float c) {
  float m = clamp(1.0f - c, 0.0f, 1.0f);
  float m2 = m * m;
  return f0 + (1.0f - f0) * (m2 * m2 * m);
}

#endif
