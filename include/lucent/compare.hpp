#pragma once
// Statistical comparison of two Monte Carlo images (docs/compare.md), and the EXR layout that
// carries what it needs: per-pixel means, sample variances and sample counts.
#include <cstddef>
#include <string>

#include "lucent/image.hpp"
#include "lucent/render.hpp"

namespace lucent {

struct CompareOptions {
  /// Family-wise significance: the probability that two renders of the same expected image fail
  /// the per-pixel test anywhere. Each of the m pixel-channels is tested at the Sidak level
  /// 1 - (1 - alpha)^(1/m), two-sided.
  double alpha = 0.01;
  /// The comparison passes when at least this fraction of the pixels pass (all their channels)
  /// and the image-mean test passes.
  double min_pass_fraction = 0.995;
  /// Added in quadrature to every pixel's standard error: abs_epsilon + rel_epsilon * |mean|.
  /// It makes zero-variance pixels (deterministic images, constant regions) a tolerance test,
  /// |A - B| <= z * (abs_epsilon + rel_epsilon * max(|A|, |B|)), and absorbs float rounding.
  double abs_epsilon = 1e-5;
  double rel_epsilon = 1e-4;
  /// Also test the mean of each channel over the whole image (z-test with the summed variances,
  /// Sidak over the three channels at `alpha`): far more sensitive to a small global bias.
  bool image_mean_test = true;
};

struct CompareResult {
  int width = 0, height = 0;
  bool passed = false;
  bool statistical = false;  ///< at least one image carried variances
  double z_threshold = 0;    ///< per pixel-channel, from alpha and the number of tests
  std::size_t tested = 0;    ///< pixel-channels tested (3 per pixel)
  std::size_t failed_channels = 0;
  std::size_t failed_pixels = 0;
  double pass_fraction = 0;      ///< pixels whose three channels pass
  double required_fraction = 0;  ///< CompareOptions::min_pass_fraction
  double max_z = 0;              ///< largest |z| over all pixel-channels
  int max_z_x = 0, max_z_y = 0, max_z_channel = 0;
  double mean_a[3] = {0, 0, 0}, mean_b[3] = {0, 0, 0};  ///< image means per channel
  double mean_z[3] = {0, 0, 0};                         ///< z of the difference of the image means
  double mean_z_threshold = 0;
  bool mean_test_passed = true;
  /// The image-mean test took image A's (B's) light-traced part from its light paths' totals
  /// (RenderResult::light_mean_variance, caustics); otherwise from its pixels, as independent.
  bool light_paths_a = false, light_paths_b = false;
  /// The largest share one pixel-channel holds of the image means' variance (the pixels' part:
  /// A's and B's var / n summed), and where; and how many samples that pixel's mean rests on, in
  /// the image holding most of its variance: mean² n / var (about k where k samples of one rare
  /// value make the mean; n / CV² for an ordinary estimate), or the excess over the other
  /// image's mean in place of the mean where the other image has under a tenth of its variance
  /// per sample (it missed the rare value: the pixel's own light is no evidence); infinite for a
  /// mean of 0 or below. Each channel is looked at: a share above 0.5 with fewer than 10 such
  /// samples is a rare, bright sample (a heavy-tailed estimate) deciding the standard
  /// error, and the image-mean |z| stays near 1 however far the means are (a near-mirror lit by a
  /// point light: means 0.33 and 0.052, z 1.000): the summary warns, and the test cannot be
  /// trusted until more samples find that value often. (A pixel whose variance is real, a small
  /// lamp, holds its share at any count: its mean then rests on many samples, and no warning.)
  double mean_variance_share = 0;
  int mean_variance_x = 0, mean_variance_y = 0, mean_variance_channel = 0;
  double mean_variance_samples = 0;
  static constexpr double kDominatedShare = 0.5;  ///< the summary warns above this share
  static constexpr double kFewSamples = 10;       ///< and below this mean_variance_samples
  /// Whether the summary warns (the two conditions above).
  bool mean_variance_dominated() const {
    return mean_variance_share > kDominatedShare && mean_variance_samples < kFewSamples;
  }
  double rmse = 0;              ///< sqrt(mean over pixel-channels of (A - B)^2)
  double relmse = 0;            ///< mean of (A - B)^2 / (B^2 + 0.01)
  double max_abs_error = 0;     ///< largest |A - B|
  Image z;                      ///< per pixel-channel z = (A - B) / standard error (signed)
  std::string summary() const;  ///< multi-line report, as `lucent compare` prints it
  /// Pixels that rest on fewer than kFewPixelSamples samples in an image carrying variances:
  /// their sample variances are unreliable (two correct renders of 2 samples per pixel failed
  /// the per-pixel test at every try, of 4 in one try of 5), and the summary warns.
  std::size_t few_sample_pixels = 0;
  static constexpr double kFewPixelSamples = 8;
  /// Failing pixel-channels where only one image carries variances and its pixel has none from
  /// fewer than kFewSamplesOfNoVariance samples (they all agreed): tested as exact, they may
  /// have missed what the pixel rarely sees, which the image without variances cannot show (a
  /// render of 32 spp failed against a converged PFM and passed against the same image as an EXR
  /// with variances). The summary warns.
  std::size_t zero_variance_failures = 0;
  static constexpr double kFewSamplesOfNoVariance = 64;
};

/// Compares two images pixel by pixel. `variance` and `samples` may be empty (a deterministic
/// image: variance 0); a pixel with fewer than 2 samples has no variance of its own. Where both
/// images carry variances, each image's per-sample variance in the per-pixel test borrows three
/// samples' worth of the other's (docs/compare.md, "The test"). Throws
/// lucent::Error when the sizes differ or an image has no pixels.
CompareResult compare_images(const RenderResult& a, const RenderResult& b,
                             const CompareOptions& options = {});

/// Throws lucent::Error "<what>: pixel (x, y) channel G is not finite (nan)" at the first
/// non-finite value of the mean or variance, and "<what>: pixel (x, y) holds no samples (n = 0)
/// ..." at the first pixel whose count (the n layer, when the image has one) is 0: input errors
/// for compare and converge, whose tests would otherwise report NaN errors or a FAIL, or take a
/// pixel without an estimate (an interrupted reference, a render whose every sample was
/// non-finite) for an exact black one and pass it.
void check_comparable_image(const RenderResult& image, const std::string& what);

/// Upper two-sided critical value of the standard normal: P(|Z| > z) = p, for p in [0, 1] (0
/// gives infinity, 1 gives 0). Throws lucent::Error for p outside it or NaN.
double normal_two_sided_critical(double p);

/// Writes an OpenEXR file with channels R, G, B (mean), var.R, var.G, var.B (sample variance of
/// one sample, float) and n (finite samples, uint), ZIP compressed. Throws lucent::Error.
void write_render_exr(const std::string& path, const RenderResult& result);

/// Reads an image for comparison: an EXR with the layers above (variance and counts filled in),
/// or any image read_image() understands (variance and samples left empty). Throws lucent::Error.
RenderResult read_render(const std::string& path);

}  // namespace lucent
