#pragma once
// Random numbers of one camera sample: the kernel's counter-based generator
// (kernels/shared/rng.h) and its dimension layout, so that both integrators draw the same numbers
// for the same (pixel, sample, dimension, seed); what they do with them is their own.
#include <cstdint>

#include "shared/rng.h"

namespace lucent::ref {

struct Sampler {
  std::uint32_t pixel, sample, seed;
  double get(std::uint32_t dim) const { return lc_rng_uniform(pixel, sample, dim, seed); }
  /// Number `offset` (LC_DIM_LIGHT_SELECT, LC_DIM_BSDF_UV, ...) of bounce `depth`.
  double bounce(int depth, std::uint32_t offset) const {
    return get(LC_DIM_BOUNCE + static_cast<std::uint32_t>(depth) * LC_DIMS_PER_BOUNCE + offset);
  }
};

/// Dimensions beyond any bounce's, for the filters' extra numbers.
constexpr std::uint32_t kDimExtra = 0x40000000u;

}  // namespace lucent::ref
