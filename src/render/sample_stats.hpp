#pragma once
// The sample statistics that every accumulation turns into a variance (uniform renders, part
// files, an adaptive render's halves, its calibration and its light paths): from running sums
// and sums of squares, never from stored samples.
#include <algorithm>

namespace lucent::render_detail {

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

}  // namespace lucent::render_detail
