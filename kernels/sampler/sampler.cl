/* lucent kernel: the random numbers of one camera sample. Every number is a pure function of
 * (sampler, pixel, sample index, dimension, seed) (shared/rng.h), with the dimension layout of
 * shared/rng.h, so an image does not depend on the device, the work-group size or the passes.
 * lc_rand2 and lc_rand4 give the numbers of an aligned pair or group of four at once (one hash
 * for the independent sampler's four); each is bit for bit what lc_rand gives for its dimensions,
 * and what the reference (src/reference/sampler.hpp) draws. */
#ifndef LUCENT_SAMPLER_SAMPLER_CL
#define LUCENT_SAMPLER_SAMPLER_CL

typedef struct {
  lc_uint pixel, sample, seed, sampler;
} lc_rng;

/* Numbers dim and dim + 1 (dim even). */
#define LC_SAMPLER_PAIR(ID, Name, value, name, feature, file) \
  if (LC_ENABLED(feature) && r->sampler == LC_SAMPLER_##ID)   \
    lc_##file##_pair(r->pixel, r->sample, dim >> 1, r->seed, w);
static inline float2 lc_rand2(const lc_rng* r, lc_uint dim) {
  lc_uint w[2] = {0u, 0u};
  LC_SAMPLER_TYPES(LC_SAMPLER_PAIR)
  return (float2)(lc_u01(w[0]), lc_u01(w[1]));
}
#undef LC_SAMPLER_PAIR

/* Numbers dim .. dim + 3 (dim a multiple of 4). */
static inline float4 lc_rand4(const lc_rng* r, lc_uint dim) {
#ifdef LC_HAS_SAMPLER_INDEPENDENT
  if (r->sampler == LC_SAMPLER_INDEPENDENT) {
    lc_uint q[4];
    lc_independent_quad(r->pixel, r->sample, dim >> 2, r->seed, q);
    return (float4)(lc_u01(q[0]), lc_u01(q[1]), lc_u01(q[2]), lc_u01(q[3]));
  }
#endif
  return (float4)(lc_rand2(r, dim), lc_rand2(r, dim + 2u));
}

static inline float lc_rand(const lc_rng* r, lc_uint dim) {
  float2 u = lc_rand2(r, dim & ~1u);
  return (dim & 1u) ? u.y : u.x;
}

#endif
