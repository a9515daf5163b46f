#pragma once
// Adaptive sampling (Renderer::render_adaptive, docs/rendering-model.md "Adaptive sampling"): the
// arithmetic of the two halves, apart from the device work so that tests can check it alone.
//
// An adaptive render keeps two independent halves of samples per pixel, A and B (streams 0 and 1:
// the seeds lc_stream_seed(seed, 0 or 1), sample indices 0, 1, 2, ... in each). Both start with
// the same pilot of m samples per pixel. The number of samples of half A in pixel p is then
// planned from half B's pilot alone, and that of half B from half A's pilot alone
// (plan_samples), and the image is the equal-weight average (A_p + B_p) / 2 of the halves'
// sample means (combine_halves).
//
// Why the mean is unbiased: half A's count N_A(p) is a function of half B's pilot, which is
// independent of every sample of half A (another stream of random numbers). So conditionally on
// N_A(p) = n, A_p is the mean of the first n samples of its stream, whose expectation is the
// pixel's value whatever n is: E[A_p] = E[E[A_p | N_A(p)]] = mu_p. Likewise E[B_p] = mu_p, and the
// weights (1/2, 1/2) are fixed, so E[(A_p + B_p) / 2] = mu_p. Each half's mean includes its own
// pilot: its count was planned from the other half's pilot (at p, its neighbours and, for the
// overall scale, every pixel), never from its own samples. What would
// bias it is a count that depends on the samples it averages (a pixel that happened to draw a
// bright sample getting more samples, so that bright draws are diluted and dark ones are not),
// including a stopping rule that looks at the half's own running error: here no count and no
// stopping decision of a half ever reads that half's samples. (A time limit or Ctrl-C cuts the
// plan by the clock: the counts then depend on how long the passes took, which depends on the
// samples only through the cost of tracing them; a render that completes its plan has none of
// this. Non-finite samples are left out and counted, as in every render.)
#include <cstddef>
#include <cstdint>
#include <vector>

namespace lucent::render_detail {

/// The relative variance of one sample of each pixel, as relMSE weighs errors (docs/compare.md):
/// (1/3) sum over channels of s^2 / (mean^2 + 0.01), from per-pixel sums, sums of squares (3
/// channels each) and sample counts; 0 for a pixel with fewer than 2 samples.
std::vector<double> relative_variance(const std::vector<double>& sum,
                                      const std::vector<double>& sumsq,
                                      const std::vector<std::uint32_t>& count);

/// A plan of per-pixel sample counts for one half.
struct SamplePlan {
  std::vector<std::uint32_t> counts;  ///< samples of each pixel, in [min_n, max_n]
  double predicted = 0;  ///< mean over pixels of v / count: the half's predicted relMSE
  double mean = 0;       ///< mean count per pixel
};

/// Plans the per-pixel sample counts of one half from the relative variances v of the other
/// half's pilot (width x height pixels): counts proportional to the square root of v (the
/// allocation that minimises sum v / n for a given sum n), where v is first raised to the mean
/// of its 3 x 3 neighbourhood (a pixel whose pilot saw little of a noisy neighbourhood still gets
/// samples), clamped to [min_n, max_n]. With target > 0 the counts are the smallest such that
/// the predicted relMSE of the half's image, mean of that raised v over n (v itself would
/// under-predict: the pixels whose pilot under-estimated v get fewer samples), is at most target (max_n everywhere
/// when even that does not reach it); otherwise the largest such that the mean count is at most
/// budget. Raising `target` or lowering `budget` never raises a count.
SamplePlan plan_samples(const std::vector<double>& v, int width, int height, double target,
                        double budget, std::uint32_t min_n, std::uint32_t max_n);

/// One pixel of an adaptive render from its two halves' sums (3 channels), sums of squares and
/// counts: mean = (mean_A + mean_B) / 2 (one half's mean alone when the other has no sample),
/// n = n_A + n_B, and var such that var / n is the variance of that mean with the pooled
/// variance s^2 of one sample: var = n s^2 (1/n_A + 1/n_B) / 4 (= s^2 when n_A = n_B).
void combine_halves(const double* sum_a, const double* sumsq_a, std::uint32_t n_a,
                    const double* sum_b, const double* sumsq_b, std::uint32_t n_b, float mean[3],
                    float var[3], std::uint32_t* n);

}  // namespace lucent::render_detail
