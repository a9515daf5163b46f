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
//
// With a target, the pilot (A's, B's and C's) is rendered without glass splitting
// (integrator.dielectric_splits; the session's unsplit passes), the samples after it with the
// scene's splits (a budget's pilot splits: its plan only shapes the counts): splitting replaces
// a lobe choice by its expectation, so the pilot's variances bound those of the split samples,
// and the unbiasedness argument is unchanged (each of a half's samples, split or not, is an
// unbiased sample of the pixel, and its count still reads only the other half's pilot).
//
// With a target error, the plan's scale comes from the model "relMSE of a pixel = v / n", which
// holds for independent samples but over-predicts for Owen-scrambled Sobol samples (their error
// falls faster). A third stream C (lc_stream_seed(seed, 2)) renders the same pilot on a sparse
// subset of pixels; C's samples are never averaged into the image. Half A's model is scaled by a
// gain measured from B's pilot and C (calibrate_model), B's from A's pilot and C: the argument
// above is unchanged, since A's counts still read nothing of A's samples.
//
// Light-traced caustics (integrator.caustics; docs/rendering-model.md): every camera sample of a
// half also traces one light path (its numbers from LC_DIM_LIGHT_PATH on, of the half's stream),
// which splats into that half's own light sums L_h (any pixel's); C's samples trace none. Half
// h's estimate of pixel p is then its camera mean plus L_h(p) / N_h, N_h the light paths it
// traced = the samples it launched (a non-finite camera sample's light path still counts), and
// the image is the average of the halves as before (add_light_halves). Unbiased by the same
// argument: N_h and which (pixel, index) pairs trace light paths are functions of half h's plan,
// which reads only the other half's pilot (camera samples and light paths) and C's, all of other
// streams; so given N_h, L_h(p) / N_h averages N_h light paths each of whose expectation is the
// light-traced part of p, and E[L_h(p) / N_h] is that part whatever N_h is. The light sums are
// per half on purpose: one image-wide light estimate over both halves' N_A + N_B paths would
// divide by a count planned from the pilots' light paths that it also averages (a pilot whose
// light paths happened to be noisy would plan more paths and dilute its own bright splats), which
// is biased. Per half, the planning half's pilot light paths plan only the other half. Within a
// half the light paths' numbers (pairs from LC_DIM_LIGHT_PATH on) are independent of its camera
// samples' for both samplers (independent: a hash of the dimension group; Sobol: each pair has
// its own scramble keys, hashed from the pair's index): unbiasedness does not need it, but the
// variance of a half's estimate is then the sum of its camera and light terms.
//
// The plan's model with caustics: relMSE of half h = g * mean_p(v_p / n_p) + w / N_h, with w
// the mean over pixels of the per-light-path relative variance from the other half's pilot
// (light_relative_variance) and N_h the sum of the plan's counts. Both terms fall as the counts
// rise, so the bisection stays monotone; the light term reads only the total, so the counts keep
// their shape sqrt(v) (an even shape when only the light term has variance). The gain scales the
// camera term only (C traces no light paths). The relative variances weigh errors by the pilot's
// whole pixel value, camera part (neighbour_values) plus light mean.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace lucent::render_detail {

/// The value that weighs a pixel's errors in the error model (relMSE's 1 / (value^2 + 0.01)):
/// per channel, the smaller of the pixel's own sample mean and the mean of its 8 neighbours'
/// (mean, 3 per pixel; a neighbour counts when present[i] > 0; the own mean alone when none is
/// present, as on a 1 x 1 film), plus add (3 per pixel) when given. The own mean alone is
/// correlated with the pixel's sample variance (a pixel whose samples drew a rare bright path has
/// both a large variance and a large mean), so s^2 / (mean^2 + 0.01) under-estimates the relative
/// variance exactly where it is large; the neighbours' mean alone over-weighs a dark pixel beside
/// a bright one (a 48 x 48 lamp scene stopped at 4.4 E with it). The smaller of the two keeps
/// the neighbours' value where the pixel drew a rare bright sample, and the dark side of an edge
/// its own; it can only over-weigh (conservative). Measured on scenes/course.json (128 x 128,
/// 155 spp, caustics, 4 renders): the variances weighed by each pixel's own mean predicted
/// 0.42-0.65 of the relMSE that the same variances weighed by the reference predict; weighed by
/// this value, 0.95-1.41.
std::vector<double> neighbour_values(const std::vector<double>& mean,
                                     const std::vector<std::uint32_t>& present, int width,
                                     int height, const std::vector<double>* add = nullptr);

/// The sample means (3 per pixel) of per-pixel sums and counts (0 without samples).
std::vector<double> sample_means(const std::vector<double>& sum,
                                 const std::vector<std::uint32_t>& count);

/// The relative variance of one sample of each pixel, as relMSE weighs errors (docs/compare.md):
/// (1/3) sum over channels of s^2 / (value^2 + 0.01), from per-pixel sums, sums of squares (3
/// channels each) and sample counts; 0 for a pixel with fewer than 2 samples. `value` (3 per
/// pixel; neighbour_values) weighs the errors; without it, the pixel's sample mean.
std::vector<double> relative_variance(const std::vector<double>& sum,
                                      const std::vector<double>& sumsq,
                                      const std::vector<std::uint32_t>& count,
                                      const std::vector<double>* value = nullptr);

/// The light paths' mean of each pixel-channel (width x height pixels), smoothed: the mean of
/// light_sum / paths over the pixel's 3 x 3 neighbourhood (0 without paths). It only weighs
/// errors (the value in relMSE's 1 / (value^2 + 0.01)): a pilot's light mean in one pixel rests
/// on a few splats, and that noise, correlated with the splats' variance, makes the mean of
/// s^2 / value^2 low (measured on the mirror scene of test_kernel_caustics.cpp: 0.63 times the
/// converged value from a 32-spp pilot, unsmoothed).
std::vector<double> light_means(const std::vector<double>& light_sum, std::uint64_t paths,
                                int width, int height);

/// The mean over pixels of the relative variance of one light path's contribution to the pixel:
/// (1/3) sum over channels of s_l^2 / (value^2 + 0.01), s_l^2 the variance over the `paths`
/// light paths of their splats to the pixel (light_sum, light_sumsq), value the pixel's whole
/// value (3 per pixel: the camera part from the neighbours, neighbour_values, plus the light
/// mean, light_means). A light estimate over N paths then has the mean relative variance w / N.
/// 0 with fewer than 2 paths.
double light_relative_variance(const std::vector<double>& light_sum,
                               const std::vector<double>& light_sumsq, std::uint64_t paths,
                               const std::vector<double>& value);

/// A plan of per-pixel sample counts for one half.
struct SamplePlan {
  std::vector<std::uint32_t> counts;  ///< samples of each pixel, in [min_n, max_n]
  double predicted = 0;  ///< gain * mean over pixels of v / count + light: predicted relMSE
  double light = 0;      ///< the light term light_w / (sum of counts)
  double mean = 0;       ///< mean count per pixel
};

/// Plans the per-pixel sample counts of one half from the relative variances v of the other half's
/// pilot (width x height pixels): counts proportional to the square root of v (the allocation that
/// minimises sum v / n for a given sum n), where v is first raised to the mean of its
/// neighbourhood, 3 x 3 for radius 1 (a pixel whose pilot saw little of a noisy neighbourhood still
/// gets samples), clamped to [min_n, max_n]. With target > 0 the counts are the smallest such that
/// the predicted relMSE of the half's image, mean of that raised v over n (v itself would
/// under-predict: the pixels whose pilot under-estimated v get fewer samples), is at most target
/// (max_n everywhere when even that does not reach it); otherwise the largest such that the mean
/// count is at most budget. Raising `target` or lowering `budget` never raises a count. `gain`
/// scales the model (calibrate_model): the predicted relMSE is gain times the mean of the raised v
/// over n (gain 1: independent samples); it plays no part in a budget's plan. `light_w` > 0
/// (caustics: light_relative_variance of the other half's pilot) adds light_w / (sum of the counts)
/// to the predicted relMSE, one light path per camera sample. `radius` (choose_radius) sizes the
/// neighbourhood whose mean raises v: (2 radius + 1)^2.
SamplePlan plan_samples(const std::vector<double>& v, int width, int height, double target,
                        double budget, std::uint32_t min_n, std::uint32_t max_n, double gain = 1,
                        double light_w = 0, int radius = 1);

/// v raised to the mean of its (2 radius + 1)^2 neighbourhood (clipped at the film's edges):
/// max(v_p, mean over the window of v).
std::vector<double> raised_variance(const std::vector<double>& v, int width, int height,
                                    int radius);

/// The calibration of the plan's error model "relMSE of a pixel = v / n" (exact for independent
/// samples; Owen-scrambled Sobol samples do better, by a factor that depends on the scene and on
/// n). A third stream C (lc_stream_seed(seed, 2)) renders a pilot on a sparse subset of the
/// pixels; at each pixel p of the subset, the pilot mean O_p of the other half (the one whose
/// pilot plans this half) and C's mean C_p are independent estimates of the same value, so
/// E[(O_p - C_p)^2] / 2 is the variance of one pilot's mean, whatever the sampler. Summed over
/// the subset's pixel-channels with relMSE's weights 1 / (value^2 + 0.01) (the value (O_p +
/// C_p) / 2) this is `measured`; `modelled` is the same sum of the model's variance of that
/// pilot mean, s^2 (1/n_O + 1/n_C) / 2 (= s^2 / m for equal counts), with s^2 the variance of one
/// sample pooled over O and C. gain = measured / modelled, clamped to [lo, hi]: ~1 for
/// independent samples, below 1 for Sobol. It reads O and C only, never the half it plans, so
/// that half's counts stay independent of its samples (the argument above).
///
/// The gain is measured at the pilot's m samples. Where Sobol's error keeps falling faster than
/// 1 / n (default, textured, the Cornell box), the calibrated model over-predicts at the larger
/// counts of a plan (conservative). Where rare high-dimensional paths carry the variance (course),
/// the gain at the pilot (0.44-0.64) is about 1 at the plan's counts, so there it under-predicts
/// (docs/rendering-model.md).
struct Calibration {
  double gain = 1;
  double measured = 0, modelled = 0;  ///< the sums above
  std::size_t pixels = 0;             ///< pixels of the subset with >= 2 samples in O and C
};
Calibration calibrate_model(const std::vector<double>& o_sum, const std::vector<double>& o_sumsq,
                            const std::vector<std::uint32_t>& o_count,
                            const std::vector<double>& c_sum, const std::vector<double>& c_sumsq,
                            const std::vector<std::uint32_t>& c_count, double lo = 1.0 / 64,
                            double hi = 4);

/// What the plans read of a finished pilot: per-pixel relative variances v (relative_variance;
/// empty for C) and the sums, sums of squares (3 channels) and counts on the calibration pixels.
struct Pilot {
  std::vector<double> v;
  double light_w = 0;  ///< caustics: light_relative_variance of the pilot's light paths
  std::vector<double> sum, sumsq;
  std::vector<std::uint32_t> count;
  std::vector<double> value;        ///< neighbour_values on the calibration pixels (not for C)
  std::vector<std::size_t> pixels;  ///< the calibration pixels (indices into the film)
};

/// The neighbourhood of plan_samples' raise for the half planned from pilot `o`, checked
/// against C, which is independent of o: at C's pixels, U_R = sum of v_C / sqrt(r_R) over the
/// sum of sqrt(r_R), with r_R = raised_variance(o.v, R) (the plan's variances; its counts go as
/// sqrt(r_R)) and v_C C's relative variances weighed by o's neighbour values (independent of
/// C's samples, so that v_C is an unbiased estimate of each pixel's relative variance). U_R is
/// the ratio of the error that the counts sqrt(r_R) would reach on C's estimate to what the
/// plan predicts: about 1 or below when o's per-pixel variances hold, above 1 when o's pilot
/// missed paths that C's drew elsewhere (rare bright paths: a pilot catches them in a few pixels
/// and misses them in the others). Returns the smallest R of 1, 2, 3, 5 with U_R <= 1.1, else 5
/// (1 when o has no values or C no pixels); `under` receives U of the radius returned. It reads
/// o and C only, never the planned half.
int choose_radius(const Pilot& o, const Pilot& c, int width, int height, double* under = nullptr);

/// Both halves' plans: half h's plan (h = 0: A, 1: B) from the other half's pilot and, with a
/// target, C's: calib[h] = calibrate_model(other, c) and plan[h] = plan_samples(other.v, ...,
/// 2 target, budget / 2, min_n, max_n, calib[h].gain, other.light_w, radius[h]) (a half at 2 E
/// makes the average of the two E), radius[h] = choose_radius(other, c). Nothing of half h's
/// pilot reaches plan[h], calib[h] or radius[h]. With a budget, calib stays at gain 1, the radius
/// at 1, and c is not read.
struct HalfPlans {
  SamplePlan plan[2];
  Calibration calib[2];
  int radius[2] = {1, 1};    ///< choose_radius (with a target; 1 for a budget)
  double under[2] = {0, 0};  ///< its U
};
HalfPlans plan_halves(const Pilot& a, const Pilot& b, const Pilot& c, int width, int height,
                      double target, double budget, std::uint32_t min_n, std::uint32_t max_n);

/// The fewest calibration pixels whose gain a plan uses: a gain measured on fewer (a film of
/// fewer pixels) is noise, and the plan takes gain 1, the model of independent samples
/// (conservative for Sobol). On a 1x1 film the gains ranged over 0.016-4 for both samplers, and
/// renders reached 2.8-3.2 E on average; at 4x4 0.6-0.8 E.
inline constexpr std::size_t kMinCalibrationPixels = 16;

/// The pixels of stream C's pilot: every `stride`-th pixel of every `stride`-th row (offset
/// stride / 2), stride the largest in 1..4 that keeps at least `min_pixels` of them (1: the
/// whole film). Returns the stride.
int calibration_stride(int width, int height, std::size_t min_pixels = 4096);

/// The a-posteriori relMSE of the average of the halves: the mean over pixel-channels of
/// (A_p - B_p)^2 / 4 / (value^2 + 0.01), value (A_p + B_p) / 2, over the pixels where both halves
/// have samples. E[(A_p - B_p)^2] / 4 is the variance of (A_p + B_p) / 2 for any sampler, counts
/// planned or not: given all of A's stream, B's count is fixed (it reads A's pilot only) and B's
/// samples are independent of A's, so E[B_p | A's stream] = mu_p; hence E[A_p B_p] = mu_p^2, the
/// halves are uncorrelated, and E[(A_p - B_p)^2] = Var A_p + Var B_p = 4 Var((A_p + B_p) / 2).
/// Noisy per pixel (one degree of freedom), fine over an image. Reported, never read by a
/// decision.
/// `value` (3 per pixel; neighbour_values of the average) weighs the errors in place of
/// (A_p + B_p) / 2, which is correlated with (A_p - B_p)^2 (neighbour_values). (The smaller
/// half's mean where lower, or its geometric mean with the neighbours' value, were tried for a
/// pixel whose rare bright sample beside a bright lamp this weight hides, and left out: at the
/// lamp's edges, where one half's samples hit it and the other's miss, they over-estimated 20 to
/// 10^4 times, docs/rendering-model.md.)
double halves_relmse(const std::vector<double>& sum_a, const std::vector<std::uint32_t>& n_a,
                     const std::vector<double>& sum_b, const std::vector<std::uint32_t>& n_b,
                     const std::vector<double>* value = nullptr);

/// One pixel of an adaptive render from its two halves' sums (3 channels), sums of squares and
/// counts: mean = (mean_A + mean_B) / 2 (one half's mean alone when the other has no sample),
/// n = n_A + n_B, and var such that var / n is the variance of that mean: var = n (s_A^2 / n_A +
/// s_B^2 / n_B) / 4 (n s_h^2 / n_h when only half h has samples), s_h^2 the variance of one
/// sample of half h from half h's own samples (from both halves pooled where n_h < 2: a render
/// cut in its pilot). Not one variance pooled over the halves: half A's count was planned from
/// B's pilot, whose samples are then correlated with n_A (a pilot that missed the bright paths
/// plans few samples and lowers a pooled s^2 exactly where s^2 / n_A is large), whereas A's own
/// s_A^2 is independent of n_A, so that E[s_A^2 / n_A] is A's variance (the argument at the top).
/// Measured on the glass lamp box with a point light outside the glass (8x8, gaussian radius 3,
/// budget 16, pilot 4, at most 64, independent sampler, 600 renders): the renders' spread over
/// the mean var / n was 1.10-1.36 with the pooled variance, 1.00-1.03 with the halves' own.
/// `half_var` (when given) receives each half's estimated variance of its mean, s_h^2 / n_h
/// (0 for a half without samples).
void combine_halves(const double* sum_a, const double* sumsq_a, std::uint32_t n_a,
                    const double* sum_b, const double* sumsq_b, std::uint32_t n_b, float mean[3],
                    float var[3], std::uint32_t* n, double half_var[2][3] = nullptr);

/// Adds the light-traced part (caustics) to a pixel combined by combine_halves (n samples): each
/// half's light estimate is its light sum over its paths_h light paths, with variance s_l^2 /
/// paths_h (s_l^2: one path's variance, from the sums of squares); the pixel's light part is
/// their average (one half's alone when the other traced none), added to mean, and its variance
/// light_var (that of the average) is added to var as n * light_var, var / n staying the
/// variance of the pixel's mean.
void add_light_halves(const double* lsum_a, const double* lsumsq_a, std::uint64_t paths_a,
                      const double* lsum_b, const double* lsumsq_b, std::uint64_t paths_b,
                      std::uint32_t n, float mean[3], float var[3], double light_var[3]);

}  // namespace lucent::render_detail
