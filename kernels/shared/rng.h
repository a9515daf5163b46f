/*
 * lucent: counter-based random numbers, shared by the kernel and the host reference integrator.
 *
 * Every random number is a pure function of (pixel, sample index, dimension, seed): the same seed
 * gives the same image whatever the device, work-group size or number of progressive passes.
 * The hash is pcg4d (Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT 2020).
 *
 * Dimension layout, shared by both integrators (see docs or integrator code):
 *   0,1 pixel filter   2,3 lens   then LC_DIMS_PER_BOUNCE numbers per bounce starting at 4.
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
#define LC_DIM_LIGHT_SELECT 0u /* choose a light                 */
#define LC_DIM_LIGHT_UV 1u     /* 2 numbers: point on the light  */
#define LC_DIM_BSDF_LOBE 3u    /* choose a lobe (glass, plastic) */
#define LC_DIM_BSDF_UV 4u      /* 2 numbers: BSDF direction      */
#define LC_DIM_RR 6u           /* Russian roulette               */

/* pcg4d: hashes four 32-bit words into four; returns the first. */
LC_RNG_FN lc_uint lc_hash4(lc_uint x, lc_uint y, lc_uint z, lc_uint w) {
  x = x * 1664525u + 1013904223u;
  y = y * 1664525u + 1013904223u;
  z = z * 1664525u + 1013904223u;
  w = w * 1664525u + 1013904223u;
  x += y * w;
  y += z * x;
  z += x * y;
  w += y * z;
  x ^= x >> 16u;
  y ^= y >> 16u;
  z ^= z >> 16u;
  w ^= w >> 16u;
  x += y * w;
  y += z * x;
  z += x * y;
  w += y * z;
  return x ^ w;
}

/* Uniform float in [0, 1) with 24 random bits; the same bits on host and device. */
LC_RNG_FN float lc_rng_uniform(lc_uint pixel, lc_uint sample, lc_uint dim, lc_uint seed) {
  return (float)(lc_hash4(pixel, sample, dim, seed) >> 8) * (1.0f / 16777216.0f);
}

#endif /* LUCENT_SHARED_RNG_H */
