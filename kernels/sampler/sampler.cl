/* lucent kernel: the random numbers of one camera sample. Every number is a pure function of
 * (sampler, pixel, sample index, dimension, seed) (shared/rng.h), with the dimension layout of
 * shared/rng.h, so an image does not depend on the device, the work-group size or the passes.
 * lc_rand2 and lc_rand8 give the numbers of an aligned pair, or of eight dimensions from a
 * multiple of 4 (one bounce's), at once; each is bit for bit what lc_rand gives for its
 * dimensions, and what the reference (src/reference/sampler.hpp) draws. lc_rand8 computes the
 * Sobol sampler's four pairs as vector operations (one lane per pair): 4.5-7% faster renders
 * than four calls of the scalar pair (BENCHMARKS.md, "Where the time goes"). */
#ifndef LUCENT_SAMPLER_SAMPLER_CL
#define LUCENT_SAMPLER_SAMPLER_CL

/* A camera sample's random-number state: its sample index and the folded words (LC_FOLD,
 * shared/rng.h) of its pixel, sample index and seed, folded once per sample (lc_rng_init,
 * lc_rng_set_sample) rather than at each number. */
typedef struct {
  lc_uint kpixel, sample, ksample, kseed, sampler;
} lc_rng;

static inline void lc_rng_init(lc_rng* r, lc_uint pixel, lc_uint seed, lc_uint sampler) {
  r->kpixel = LC_FOLD(pixel);
  r->kseed = LC_FOLD(seed);
  r->sampler = sampler;
  r->sample = r->ksample = 0u;
}
static inline void lc_rng_set_sample(lc_rng* r, lc_uint sample) {
  r->sample = sample;
  r->ksample = LC_FOLD(sample);
}

/* Numbers dim and dim + 1 (dim even). */
#define LC_SAMPLER_PAIR(ID, Name, value, name, feature, file) \
  if (LC_ENABLED(feature) && r->sampler == LC_SAMPLER_##ID)   \
    lc_##file##_pair_k(r->kpixel, r->sample, r->ksample, dim >> 1, r->kseed, w);
static inline float2 lc_rand2(const lc_rng* r, lc_uint dim) {
  lc_uint w[2] = {0u, 0u};
  LC_SAMPLER_TYPES(LC_SAMPLER_PAIR)
  return (float2)(lc_u01(w[0]), lc_u01(w[1]));
}
#undef LC_SAMPLER_PAIR

/* Each sampler's lc_<file>_pairs4 (the registry's file name, as its lc_<file>_pair in
 * shared/rng.h): the words of pairs pair .. pair + 3 (pair even), bit for bit those of its pair
 * function, computed together. */

/* Sobol: lc_sobol_pair with rng.h's word operations on vectors (lane k: pair + k): the four keys,
 * shuffles and eight scrambles take the instructions of one, their chains of multiplications
 * overlapped. */
static inline uint8 lc_sobol_pairs4(lc_uint kpixel, lc_uint sample, lc_uint ksample, lc_uint pair,
                                    lc_uint kseed) {
  uint4 x = (uint4)(kpixel), y = LC_FOLD((uint4)(pair) + (uint4)(0u, 1u, 2u, 3u));
  uint4 z = (uint4)(kseed), w = (uint4)(0x50b01u);
  (void)ksample;
  LC_PCG4D(x, y, z, w)
  uint4 i = (uint4)(lc_reverse_bits(sample)); /* the shuffled index, as in lc_sobol_pair */
  LC_OWEN_HASH(i, x)
  LC_REVERSE_BITS(i)
  uint4 j = i;
  LC_SOBOL1_REVERSED(j)
  uint8 v = (uint8)(i.s0, j.s0, i.s1, j.s1, i.s2, j.s2, i.s3, j.s3);
  uint8 k = (uint8)(y.s0, z.s0, y.s1, z.s1, y.s2, z.s2, y.s3, z.s3);
  LC_OWEN_HASH(v, k)
  LC_REVERSE_BITS(v)
  return v;
}

/* Independent: two quads, scalar (in uint2 lanes they measured 2% slower). */
static inline uint8 lc_independent_pairs4(lc_uint kpixel, lc_uint sample, lc_uint ksample,
                                          lc_uint pair, lc_uint kseed) {
  lc_uint a[4], c[4];
  (void)sample;
  lc_independent_quad_k(kpixel, ksample, pair >> 1, kseed, a);
  lc_independent_quad_k(kpixel, ksample, (pair >> 1) + 1u, kseed, c);
  return (uint8)(a[0], a[1], a[2], a[3], c[0], c[1], c[2], c[3]);
}

/* Numbers dim .. dim + 7 (dim a multiple of 4): one bounce's, or a light path vertex's. */
#define LC_SAMPLER_PAIRS4(ID, Name, value, name, feature, file) \
  if (LC_ENABLED(feature) && r->sampler == LC_SAMPLER_##ID)     \
    q = lc_##file##_pairs4(r->kpixel, r->sample, r->ksample, dim >> 1, r->kseed);
static inline float8 lc_rand8(const lc_rng* r, lc_uint dim) {
  uint8 q = (uint8)(0u);
  LC_SAMPLER_TYPES(LC_SAMPLER_PAIRS4)
  return convert_float8(q >> 8u) * (1.0f / 16777216.0f); /* lc_u01 */
}
#undef LC_SAMPLER_PAIRS4

static inline float lc_rand(const lc_rng* r, lc_uint dim) {
  float2 u = lc_rand2(r, dim & ~1u);
  return (dim & 1u) ? u.y : u.x;
}

#endif
