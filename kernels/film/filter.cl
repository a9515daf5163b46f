/* lucent kernel: pixel reconstruction filters by importance sampling. The sample offset is drawn
 * from the filter's own distribution (pbrt-v4's filter importance sampling), so every sample has
 * weight 1 and a pixel's value is the plain mean of its samples: its variance estimate is exact. */
#ifndef LUCENT_FILM_FILTER_CL
#define LUCENT_FILM_FILTER_CL

/* Inverse CDF of the tent of radius r on [-r, r]. */
static inline float filter_sample_tent(float u, float r) {
  return u < 0.5f ? r * (sqrt(2.0f * u) - 1.0f) : r * (1.0f - sqrt(2.0f - 2.0f * u));
}

/* Offset from the pixel centre, in pixels. Gaussian: standard deviation radius / 3, truncated at
 * radius (Box-Muller, resampled radially). */
static inline float2 filter_sample(lc_uint type, float radius, float u1, float u2) {
#ifdef LC_HAS_FILTER_TENT
  if (type == LC_FILTER_TENT)
    return (float2)(filter_sample_tent(u1, radius), filter_sample_tent(u2, radius));
#endif
#ifdef LC_HAS_FILTER_GAUSSIAN
  if (type == LC_FILTER_GAUSSIAN) {
    float sigma = radius / 3.0f;
    /* truncated radial Gaussian: invert the CDF of r restricted to [0, radius]; its mass within
     * radius = 3 sigma is 1 - exp(-9 / 2) */
    const float tail = 0.98889100346175773f;
    float r = sigma * sqrt(-2.0f * log(1.0f - u1 * tail));
    return r * lc_unit_circle(u2);
  }
#endif
  return (float2)((u1 - 0.5f) * 2.0f * radius, (u2 - 0.5f) * 2.0f * radius);
}

#endif
