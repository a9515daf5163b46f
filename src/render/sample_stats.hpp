#pragma once
// The sample statistics that every accumulation turns into a variance (uniform renders, part
// files, an adaptive render's halves, its calibration and its light paths): from running sums
// and sums of squares, never from stored samples.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lucent/error.hpp"
#include "lucent/render.hpp"

namespace lucent::render_detail {

/// Whether no pixel holds a sample (every count 0).
inline bool holds_no_sample(const std::vector<std::uint32_t>& counts) {
  return std::all_of(counts.begin(), counts.end(), [](std::uint32_t n) { return n == 0; });
}

/// Refuses to write the image `path` of pixel counts `counts` when every one of its samples was
/// non-finite: it holds no estimate, and a black file would pass for one (`compare` passed it
/// against a black render). Throws lucent::Error "<path>: not written: ...". (lucent render,
/// merge and lucent-mpi; a part file keeps its counts instead.)
inline void check_some_sample_finite(const std::string& path, std::uint64_t nonfinite,
                                     const std::vector<std::uint32_t>& counts) {
  if (nonfinite > 0 && !counts.empty() && holds_no_sample(counts))
    throw Error(path + ": not written: all " + std::to_string(nonfinite) +
                " samples were non-finite (NaN or Inf, or a square beyond a float's range: a "
                "radiance or intensity above about 1.8e19?)");
}

/// The warning of `nonfinite` dropped samples (without "lucent: warning: "), with the pixels they
/// left without any sample, which are black (and which `compare` refuses), of `counts` when given.
inline std::string nonfinite_warning(std::uint64_t nonfinite,
                                     const std::vector<std::uint32_t>& counts) {
  std::size_t empty = 0;
  for (const std::uint32_t n : counts) empty += n == 0;
  std::string s = std::to_string(nonfinite) +
                  " non-finite sample(s) (NaN or Inf, or a square beyond a float's range) were "
                  "dropped";
  if (empty > 0) s += "; " + std::to_string(empty) + " pixel(s) hold no sample and are black";
  return s;
}

/// The unbiased variance of one sample, from n samples' sum and sum of squares; 0 below 2 samples
/// (and never negative: the sums' rounding can make it so).
inline double sample_variance(double sum, double sumsq, double n) {
  return n > 1 ? std::max(0.0, (sumsq - sum * (sum / n)) / (n - 1)) : 0;
}

/// The variance of one sample pooled over two groups of samples of the same variance but maybe
/// different means (squared deviations from each group's own mean, over n_a + n_b minus the
/// number of non-empty groups degrees of freedom); 0 without a degree of freedom.
inline double pooled_variance(double sum_a, double sumsq_a, double n_a, double sum_b,
                              double sumsq_b, double n_b) {
  double ss = 0;
  if (n_a > 0) ss += std::max(0.0, sumsq_a - sum_a * (sum_a / n_a));
  if (n_b > 0) ss += std::max(0.0, sumsq_b - sum_b * (sum_b / n_b));
  const double dof = n_a + n_b - double(n_a > 0) - double(n_b > 0);
  return dof > 0 ? ss / dof : 0;
}

/// integrator.caustics: per channel, the sums of the light paths' totals (a path's shares added
/// over all pixels: its contribution to the film's sum) and of their squares (megakernel.cl).
struct LightTotals {
  double sum[3] = {0, 0, 0}, sumsq[3] = {0, 0, 0};
};

/// The variance of the image mean's light part, per channel, from `paths` light paths' totals on
/// a film of `npix` pixels (LightMeanVariance::paths): a total over npix is one
/// path's contribution to the image mean, and the light part its mean over the paths.
inline void light_paths_variance(const LightTotals& t, std::uint64_t paths, double npix,
                                 double out[3]) {
  const double n = double(paths);
  for (int c = 0; c < 3; ++c)
    out[c] = paths > 1 ? sample_variance(t.sum[c], t.sumsq[c], n) / n / (npix * npix) : 0;
}

/// `v` when all its numbers are finite, else none (a float device's sums of squares of the
/// light paths' totals can overflow: compare then takes the pixels as independent).
inline std::optional<LightMeanVariance> finite_or_none(const LightMeanVariance& v) {
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(v.paths[c]) || !std::isfinite(v.pixels[c])) return std::nullopt;
  return v;
}

}  // namespace lucent::render_detail
