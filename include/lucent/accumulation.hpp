#pragma once
// The raw accumulation of a render: per-pixel double sums, sums of squares and finite-sample
// counts of the samples [first_sample, first_sample + spp). Renders are a pure function of
// (pixel, sample index, dimension, seed), so accumulations of disjoint sample ranges of the same
// scene add up to the accumulation of their union (lucent/parts.hpp merges them).
#include <cstdint>
#include <vector>

namespace lucent {

struct Accumulation {
  int width = 0;
  int height = 0;
  std::vector<double> sum;           ///< width * height * 3 (RGB), row 0 at the top
  std::vector<double> sumsq;         ///< the same layout: sums of squared samples
  std::vector<std::uint32_t> count;  ///< finite samples per pixel
  /// integrator.caustics: the light paths' per-pixel sums of contributions and of their squares
  /// (same layout; empty without caustics) and their number (docs/rendering-model.md)
  std::vector<double> light_sum, light_sumsq;
  std::uint64_t light_paths = 0;
  std::uint64_t first_sample = 0;  ///< index of the first sample accumulated
  std::uint64_t spp = 0;           ///< samples per pixel launched: [first_sample, +spp)
  std::uint64_t nonfinite = 0;     ///< NaN/Inf samples dropped and counted
  std::uint64_t rays = 0;          ///< rays traced
  double seconds = 0;              ///< kernel time
};

}  // namespace lucent
