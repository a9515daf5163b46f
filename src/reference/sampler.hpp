#pragma once
// Random numbers of one camera sample: the kernel's samplers (kernels/shared/rng.h, compiled here
// as C++) and their dimension layout, so that both integrators draw the same numbers for the same
// (sampler, pixel, sample, dimension, seed); what they do with them is their own.
#include <cstdint>

#include "lucent/scene.hpp"
#include "shared/rng.h"

namespace lucent::ref {

struct Sampler {
  std::uint32_t pixel, sample, seed;
  SamplerType type = SamplerType::Sobol;

  double get(std::uint32_t dim) const {
    lc_uint w[2];
    if (type == SamplerType::Sobol)
      lc_sobol_pair(pixel, sample, dim >> 1, seed, w);
    else
      lc_independent_pair(pixel, sample, dim >> 1, seed, w);
    return lc_u01(w[dim & 1u]);
  }
  /// Number `offset` (LC_DIM_LIGHT_SELECT, LC_DIM_BSDF_UV, ...) of bounce `depth`.
  double bounce(int depth, std::uint32_t offset) const {
    return get(LC_DIM_BOUNCE + static_cast<std::uint32_t>(depth) * LC_DIMS_PER_BOUNCE + offset);
  }
};

/// Dimensions beyond any bounce's, for the filters' extra numbers (pairs from here on).
constexpr std::uint32_t kDimExtra = 0x40000000u;

}  // namespace lucent::ref
