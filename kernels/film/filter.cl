/* lucent kernel: pixel reconstruction filters by importance sampling. The sample offset is drawn
 * from the filter's own distribution (pbrt-v4's filter importance sampling), so every sample has
 * weight 1 and a pixel's value is the plain mean of its samples: its variance estimate is exact.
 * Each filter of shared/registry.h (LC_FILTER_TYPES) is a function
 *   float2 filter_sample_<file>(float radius, float u1, float u2)
 * giving the offset from the pixel centre in pixels; filter_sample dispatches on the type. */
#ifndef LUCENT_FILM_FILTER_CL
#define LUCENT_FILM_FILTER_CL

/* uniform over the square [-radius, radius]^2 */
static inline float2 filter_sample_box(float radius, float u1, float u2) {
  return (float2)((u1 - 0.5f) * 2.0f * radius, (u2 - 0.5f) * 2.0f * radius);
}

/* Inverse CDF of the tent of radius r on [-r, r]. */
static inline float filter_sample_tent1(float u, float r) {
  return u < 0.5f ? r * (sqrt(2.0f * u) - 1.0f) : r * (1.0f - sqrt(2.0f - 2.0f * u));
}

/* separable tent */
static inline float2 filter_sample_tent(float radius, float u1, float u2) {
  return (float2)(filter_sample_tent1(u1, radius), filter_sample_tent1(u2, radius));
}

/* Gaussian of standard deviation radius / 3, truncated at radius (Box-Muller, resampled
 * radially): invert the CDF of r restricted to [0, radius]; its mass within radius = 3 sigma is
 * 1 - exp(-9 / 2). */
static inline float2 filter_sample_gaussian(float radius, float u1, float u2) {
  float sigma = radius / 3.0f;
  const float tail = 0.98889100346175773f;
  float r = sigma * sqrt(-2.0f * log(1.0f - u1 * tail));
  return r * lc_unit_circle(u2);
}

/* The normalized densities of the offsets drawn above (light tracing splats with them,
 * integrator/caustics.cl): filter_density_<file>(radius, dx, dy). */
static inline float filter_density_box(float r, float dx, float dy) {
  return (fabs(dx) <= r && fabs(dy) <= r) ? 1.0f / (4.0f * r * r) : 0.0f;
}
static inline float filter_density_tent1(float t, float r) {
  return fmax(0.0f, r - fabs(t)) / (r * r);
}
static inline float filter_density_tent(float r, float dx, float dy) {
  return filter_density_tent1(dx, r) * filter_density_tent1(dy, r);
}
static inline float filter_density_gaussian(float r, float dx, float dy) {
  float sigma = r / 3.0f, rho2 = dx * dx + dy * dy;
  if (rho2 > r * r) return 0.0f;
  const float tail = 0.98889100346175773f;
  return exp(-rho2 / (2.0f * sigma * sigma)) / (2.0f * LC_PI * sigma * sigma * tail);
}

#define LC_FILTER_SAMPLE(ID, Name, value, name, feature, file, radius_default) \
  if (LC_ENABLED(feature) && type == LC_FILTER_##ID) return filter_sample_##file(radius, u1, u2);
/* Offset from the pixel centre, in pixels. */
static inline float2 filter_sample(lc_uint type, float radius, float u1, float u2) {
  LC_FILTER_TYPES(LC_FILTER_SAMPLE)
  return (float2)(0.0f);
}
#undef LC_FILTER_SAMPLE

#define LC_FILTER_DENSITY(ID, Name, value, name, feature, file, radius_default) \
  if (LC_ENABLED(feature) && type == LC_FILTER_##ID) return filter_density_##file(radius, dx, dy);
/* Density of the offset (dx, dy) from the pixel centre, in pixels^-2. */
static inline float filter_density(lc_uint type, float radius, float dx, float dy) {
  LC_FILTER_TYPES(LC_FILTER_DENSITY)
  return 0.0f;
}
#undef LC_FILTER_DENSITY

#endif
