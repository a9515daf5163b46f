/* lucent kernel: the random numbers of one camera sample. Every number is a pure function of
 * (pixel, sample index, dimension, seed) (shared/rng.h), with the dimension layout of
 * shared/rng.h, so an image does not depend on the device, the work-group size or the passes. */
#ifndef LUCENT_SAMPLER_SAMPLER_CL
#define LUCENT_SAMPLER_SAMPLER_CL

typedef struct {
  lc_uint pixel, sample, seed;
} lc_rng;

static inline float lc_rand(const lc_rng* r, lc_uint dim) {
  return lc_rng_uniform(r->pixel, r->sample, dim, r->seed);
}

#endif
