/*
 * lucent: the random numbers of a camera sample, shared by the kernel (sampler/sampler.cl) and
 * the host reference integrator (src/reference/sampler.hpp), in plain C.
 *
 * Every number is a pure function of (sampler, pixel, sample index, dimension, seed): the same
 * seed gives the same image whatever the device, work-group size, number of progressive passes
 * or devices, and pixel p's k-th sample always draws the same numbers (adaptive sampling gives
 * pixels different sample ranges). Numbers are floats in [0, 1) with 24 random bits.
 *
 * Dimension layout, shared by both integrators. Dimensions come in aligned pairs (2k, 2k + 1),
 * and every 2D quantity is one pair, so that a low-discrepancy sampler stratifies it in 2D:
 *   0,1  pixel filter offset       2,3  lens point
 *   then LC_DIMS_PER_BOUNCE = 8 per bounce, from LC_DIM_BOUNCE + 8 * depth:
 *   +0,+1 point on the light   +2 light selection, +3 BSDF lobe   +4,+5 BSDF direction
 *   +6 Russian roulette, +7 the point inside an environment map's texel (with +1; +0 picks
 *   the texel)
 * Groups of four (4k .. 4k + 3) are what one call of lc_independent_quad gives; lc_*_pair give
 * one pair. The reference's filters draw extra pairs from dimension 0x40000000 on.
 *
 * Samplers (shared/registry.h, LC_SAMPLER_TYPES):
 *  - independent: pcg4d (Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT 2020) of
 *    (pixel, sample, dimension / 4, seed), each word folded first (LC_FOLD); its four output
 *    words are the numbers of the four dimensions of the group (one hash per four numbers).
 *  - sobol: Owen-scrambled Sobol as in Burley, "Practical Hash-based Owen Scrambling" (JCGT
 *    2020), padded by pairs: every pair of dimensions is its own shuffled and scrambled copy of
 *    the first two Sobol dimensions (a (0,2)-sequence). For pair g of pixel p a pcg4d of
 *    (p, g, seed), each word folded first (LC_FOLD), gives three keys: the sample index is
 *    shuffled by a nested uniform scramble keyed by the first (the first 2^k samples of any
 *    pixel map to an aligned block of 2^k Sobol points), and each of the two coordinates is
 *    Owen-scrambled (nested uniform scrambling by a hash) keyed by the second and third. So the
 *    first 2^k samples of every pair of every pixel form a (0,k,2)-net (every elementary box of
 *    area 2^-k holds one point), each point is uniform on [0,1)^2, and pairs and pixels are
 *    decorrelated by their independent keys. The per-digit hash is Vegdahl's improved
 *    Laine-Karras permutation ("Building a Better LK Hash", 2021), applied to bit-reversed
 *    values.
 */
#ifndef LUCENT_SHARED_RNG_H
#define LUCENT_SHARED_RNG_H

#include "shared/types.h"

#define LC_RNG_FN static inline

#define LC_DIM_FILTER 0u
#define LC_DIM_LENS 2u
#define LC_DIM_BOUNCE 4u
#define LC_DIMS_PER_BOUNCE 8u
/* offsets inside one bounce */
#define LC_DIM_LIGHT_UV 0u     /* pair: point on the light                            */
#define LC_DIM_LIGHT_SELECT 2u /* pair with the lobe: choose a light                  */
#define LC_DIM_BSDF_LOBE 3u    /* choose a lobe (glass, plastic)                      */
#define LC_DIM_BSDF_UV 4u      /* pair: BSDF direction                                */
#define LC_DIM_RR 6u           /* pair with the next: Russian roulette                */
#define LC_DIM_LIGHT_TEXEL 7u  /* across an env. map's texel (down: LC_DIM_LIGHT_UV+1) */
/* The light path of a camera sample (integrator.caustics, docs/rendering-model.md): from
 * LC_DIM_LIGHT_PATH, +0,+1 point on the light, +2 light selection, +4,+5 emitted direction (the
 * kernel's point light, which has no point to draw, takes its direction from +0,+1); then
 * 8 per scattering vertex i = 1, 2, ... from LC_DIM_LIGHT_PATH + 8 i with the offsets above
 * (+0,+1 the lens point of the vertex's connection to a thin-lens camera, +3 lobe, +4,+5 BSDF
 * direction, +6 Russian roulette). */
#define LC_DIM_LIGHT_PATH 0x20000000u

/* pcg4d: hashes the four 32-bit words x, y, z, w into four, in place. A statement macro, so that
 * the kernel can hash several keys at once in vector lanes (sampler/sampler.cl); lc_pcg4d is the
 * scalar function. */
#define LC_PCG4D(x, y, z, w)      \
  x = x * 1664525u + 1013904223u; \
  y = y * 1664525u + 1013904223u; \
  z = z * 1664525u + 1013904223u; \
  w = w * 1664525u + 1013904223u; \
  x += y * w;                     \
  y += z * x;                     \
  z += x * y;                     \
  w += y * z;                     \
  x ^= x >> 16u;                  \
  y ^= y >> 16u;                  \
  z ^= z >> 16u;                  \
  w ^= w >> 16u;                  \
  x += y * w;                     \
  y += z * x;                     \
  z += x * y;                     \
  w += y * z;

/* The hashes' input words (pixel, sample, dimension group or pair, seed) are folded, x ^ x >> 16,
 * before pcg4d: its multiplications carry a difference only towards the higher bits and its one
 * shift brings bits down by 16, so inputs that differ only in their top bits (above bit ~27)
 * gave numbers that are far from independent: two renders with the independent sampler of seeds
 * s and s + 2^31 drew almost the same number in dimension 4 of sample 0 in every pixel (its top 4
 * bits a function of the other's: 4.0 bits of mutual information of 4), samples k and k + 2^31
 * of a pixel shared up to 1.2 bits, and the Sobol keys of seeds s and s + 2^28 .. 2^31
 * correlated every odd pair (lens, light selection and lobe, Russian roulette; 0.46 bits at
 * 2^31). Folded, the top bits reach bits 0..15 before the first multiplication. Words below 2^16
 * (film pixels up to 256 x 256, small seeds, sample indices and dimensions) are unchanged, so
 * their numbers are pcg4d's. tests/test_sampling.cpp:
 * SamplerNumbers.IndependentWhenInputsDifferInTheirTopBits. */
#define LC_FOLD(x) ((x) ^ ((x) >> 16))

LC_RNG_FN void lc_pcg4d(lc_uint v[4]) {
  lc_uint x = v[0], y = v[1], z = v[2], w = v[3];
  LC_PCG4D(x, y, z, w)
  v[0] = x;
  v[1] = y;
  v[2] = z;
  v[3] = w;
}

/* The float in [0, 1) of a 32-bit word's top 24 bits: the same bits on host and device. */
LC_RNG_FN float lc_u01(lc_uint x) { return (float)(x >> 8) * (1.0f / 16777216.0f); }

/* ---- independent sampler ------------------------------------------------------------------ */

/* The words of dimensions 4 group .. 4 group + 3, from the folded words kpixel = LC_FOLD(pixel),
 * ksample = LC_FOLD(sample) and kseed = LC_FOLD(seed), which the kernel folds once per sample
 * (sampler/sampler.cl's lc_rng: folding them at every call cost 0.8% of the Cornell box's
 * render). */
LC_RNG_FN void lc_independent_quad_k(lc_uint kpixel, lc_uint ksample, lc_uint group, lc_uint kseed,
                                     lc_uint out[4]) {
  out[0] = kpixel;
  out[1] = ksample;
  out[2] = LC_FOLD(group);
  out[3] = kseed;
  lc_pcg4d(out);
}
LC_RNG_FN void lc_independent_quad(lc_uint pixel, lc_uint sample, lc_uint group, lc_uint seed,
                                   lc_uint out[4]) {
  lc_independent_quad_k(LC_FOLD(pixel), LC_FOLD(sample), group, LC_FOLD(seed), out);
}

/* The words of dimensions 2 pair and 2 pair + 1 (the sample's index and its folded word: each
 * sampler's pair function takes both, and uses what it needs). */
LC_RNG_FN void lc_independent_pair_k(lc_uint kpixel, lc_uint sample, lc_uint ksample, lc_uint pair,
                                     lc_uint kseed, lc_uint out[2]) {
  lc_uint q[4];
  (void)sample;
  lc_independent_quad_k(kpixel, ksample, pair >> 1, kseed, q);
  out[0] = q[(pair & 1u) * 2u];
  out[1] = q[(pair & 1u) * 2u + 1u];
}
LC_RNG_FN void lc_independent_pair(lc_uint pixel, lc_uint sample, lc_uint pair, lc_uint seed,
                                   lc_uint out[2]) {
  lc_independent_pair_k(LC_FOLD(pixel), sample, LC_FOLD(sample), pair, LC_FOLD(seed), out);
}

/* One number of the independent sampler (the chi-square probes' random numbers too). */
LC_RNG_FN float lc_rng_uniform(lc_uint pixel, lc_uint sample, lc_uint dim, lc_uint seed) {
  lc_uint q[4];
  lc_independent_quad(pixel, sample, dim >> 2, seed, q);
  return lc_u01(q[dim & 3u]);
}

/* ---- Owen-scrambled Sobol ----------------------------------------------------------------- */

/* The Sobol sampler's word operations are statement macros on x in place (scalars here, vectors
 * of words in the kernel's lc_sobol_pairs4), each with its scalar function. */
#define LC_REVERSE_BITS(x)                                 \
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1); \
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2); \
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4); \
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8); \
  x = (x >> 16) | (x << 16);
LC_RNG_FN lc_uint lc_reverse_bits(lc_uint x) {
  LC_REVERSE_BITS(x)
  return x;
}

/* A random bijection of 32-bit words in which bit k of the result depends only on bits 0..k of x
 * (each step is an add, a multiplication by an odd number or x ^= x * even): applied to
 * bit-reversed digits it flips each digit by a hash of the digits before it, a nested uniform
 * (Owen) scramble. Vegdahl's constants. */
#define LC_OWEN_HASH(x, seed) \
  x ^= x * 0x3d20adeau;       \
  x += seed;                  \
  x *= (seed >> 16) | 1u;     \
  x ^= x * 0x05526c56u;       \
  x ^= x * 0x53a22864u;
LC_RNG_FN lc_uint lc_owen_hash(lc_uint x, lc_uint seed) {
  LC_OWEN_HASH(x, seed)
  return x;
}

/* The second Sobol dimension of index i with its digits bit-reversed (bit j = digit j + 1 after
 * the point). Its generator matrix is Pascal's triangle mod 2: digit j is the parity of the bits
 * k of i with C(k, j) odd, i.e. (Lucas) with j a subset of k, a superset sum done in five
 * steps. The first dimension, reversed, is i itself. */
#define LC_SOBOL1_REVERSED(i)  \
  i ^= (i >> 1) & 0x55555555u; \
  i ^= (i >> 2) & 0x33333333u; \
  i ^= (i >> 4) & 0x0f0f0f0fu; \
  i ^= (i >> 8) & 0x00ff00ffu; \
  i ^= (i >> 16) & 0x0000ffffu;
LC_RNG_FN lc_uint lc_sobol1_reversed(lc_uint i) {
  LC_SOBOL1_REVERSED(i)
  return i;
}

/* The words of dimensions 2 pair and 2 pair + 1 of sample `sample` of pixel `pixel`, from the
 * folded words of the pixel and the seed (the index is not folded: it is scrambled itself). */
LC_RNG_FN void lc_sobol_pair_k(lc_uint kpixel, lc_uint sample, lc_uint ksample, lc_uint pair,
                               lc_uint kseed, lc_uint out[2]) {
  lc_uint key[4];
  (void)ksample;
  key[0] = kpixel;
  key[1] = LC_FOLD(pair);
  key[2] = kseed;
  key[3] = 0x50b01u; /* keys differ from the independent sampler's words */
  lc_pcg4d(key);
  /* shuffled index: nested uniform scramble of the sample index (on its reversed bits) */
  lc_uint i = lc_reverse_bits(lc_owen_hash(lc_reverse_bits(sample), key[0]));
  out[0] = lc_reverse_bits(lc_owen_hash(i, key[1]));
  out[1] = lc_reverse_bits(lc_owen_hash(lc_sobol1_reversed(i), key[2]));
}
LC_RNG_FN void lc_sobol_pair(lc_uint pixel, lc_uint sample, lc_uint pair, lc_uint seed,
                             lc_uint out[2]) {
  lc_sobol_pair_k(LC_FOLD(pixel), sample, LC_FOLD(sample), pair, LC_FOLD(seed), out);
}

/* The stream seed of half `stream` of an adaptive render (session.cpp): stream 0 is the seed
 * itself, so that its samples are those of a uniform render; stream 1 is independent of it. */
LC_RNG_FN lc_uint lc_stream_seed(lc_uint seed, lc_uint stream) {
  if (stream == 0u) return seed;
  lc_uint k[4];
  k[0] = seed;
  k[1] = stream;
  k[2] = 0x5eedu;
  k[3] = 0xada97u;
  lc_pcg4d(k);
  return k[0];
}

#endif /* LUCENT_SHARED_RNG_H */
