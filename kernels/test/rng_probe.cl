/* lucent test kernel: the megakernel's random numbers (sampler/sampler.cl), for the host to check
 * bit for bit against shared/rng.h's scalar pair and quad (tests/test_sampling.cpp). Query i =
 * (pixel, sample, dim, seed) with dim a multiple of 4; out[10 i .. 10 i + 7] = lc_rand8(dim),
 * out[10 i + 8, + 9] = lc_rand2(dim), all with the sampler `sampler`. Build with both samplers'
 * LC_HAS_SAMPLER_* defines. */
/* clang-format off */
#include "shared/types.h"
#include "shared/rng.h"
#include "sampler/sampler.cl"
/* clang-format on */

__kernel void probe_rng(__global const uint4* query, uint sampler, __global float* out) {
  size_t i = get_global_id(0);
  uint4 q = query[i];
  lc_rng r;
  lc_rng_init(&r, q.x, q.w, sampler);
  lc_rng_set_sample(&r, q.y);
  vstore8(lc_rand8(&r, q.z), 0, out + 10 * i);
  vstore2(lc_rand2(&r, q.z), 0, out + 10 * i + 8);
}
