// Statistical comparison of two Monte Carlo images: per pixel-channel z-tests of the difference
// of the means with both standard errors, Sidak-corrected over the image, plus an image-mean
// test and the usual error metrics. See docs/compare.md.
#include "lucent/compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "lucent/error.hpp"
#include "scene/validate.hpp"

namespace lucent {

double normal_two_sided_critical(double p) {
  // (NaN gave 0, a threshold every difference passes)
  if (!(p >= 0 && p <= 1))
    throw Error("normal_two_sided_critical: p must be a probability in [0, 1], got " +
                scene_detail::format_number(p));
  if (p == 1) return 0;
  if (p == 0) return INFINITY;
  // P(|Z| > z) = erfc(z / sqrt 2) decreases in z: bisect
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    double mid = 0.5 * (lo + hi);
    if (std::erfc(mid / std::sqrt(2.0)) > p)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

namespace {

/// The number of samples of pixel i (1 without counts).
double sample_count(const RenderResult& r, size_t i) {
  return r.samples.empty() ? 1.0 : static_cast<double>(r.samples[i]);
}

/// The sample variance of one sample of pixel i, channel c (0 when unknown: no variance layers,
/// or fewer than 2 samples).
double per_sample_variance(const RenderResult& r, size_t i, int c) {
  if (r.variance.rgb.empty() || sample_count(r, i) < 2) return 0;
  return std::max(0.0, static_cast<double>(r.variance.rgb[i * 3 + c]));
}

/// Variance of the mean of pixel i, channel c (0 when unknown).
double variance_of_mean(const RenderResult& r, size_t i, int c) {
  const double v = per_sample_variance(r, i, c);
  return v > 0 ? v / sample_count(r, i) : 0;
}

/// The per-pixel test's variance of A - B at pixel i, channel c. Where both images carry
/// variances, each image's per-sample variance borrows kPriorSamples samples' worth of the
/// other's: s'_A = ((n_A - 1) s_A + k s_B) / (n_A - 1 + k), k = 3. A pixel's sample variance from
/// few samples misses what the pixel rarely sees (a sphere's silhouette that none of 32 samples hit
/// has variance 0; a dark pixel that missed rare bright paths, nearly 0), and the render of few
/// samples failed against a converged reference of the same renderer at every try (32 against
/// 16384 spp: 10 runs in 10); under the hypothesis tested (the same expected value) the other
/// image's spread is evidence of the pixel's. An image of many samples keeps nearly its own (the
/// larger of the two, the first version, took a kernel of 64 spp and variance 0.01 as if it
/// had the variance 1 of a reference of 4096: a local bias of 25% passed, z 2 where it was 12.5).
/// k = 3 is the rule of three: n samples that all missed an event leave it a probability of up
/// to about 3 / n, and the variance it would add, about 3 / n of the other image's, is what a
/// sample variance of 0 borrows. The image-mean test keeps each image's own variances (its
/// power; a pixel's missed tail averages out there).
constexpr double kPriorSamples = 3;
double pixel_test_variance(const RenderResult& a, const RenderResult& b, size_t i, int c) {
  if (a.variance.rgb.empty() || b.variance.rgb.empty())
    return variance_of_mean(a, i, c) + variance_of_mean(b, i, c);
  const double sa = per_sample_variance(a, i, c), sb = per_sample_variance(b, i, c);
  const double na = sample_count(a, i), nb = sample_count(b, i);
  // (fewer than 2 samples: no variance of its own, the other's)
  const auto pooled = [](double own, double n, double other) {
    const double dof = n >= 2 ? n - 1 : 0;
    return (dof * own + kPriorSamples * other) / (dof + kPriorSamples);
  };
  return (na > 0 ? pooled(sa, na, sb) / na : 0) + (nb > 0 ? pooled(sb, nb, sa) / nb : 0);
}

/// How many samples the mean of pixel i, channel c rests on, in the image (X) holding most of
/// its variance: mean² / (var / n), about k where k samples of one rare value V make it. Where
/// the other image (Y) has far less variance per sample there, it missed that value, and the
/// excess of X over Y is what the rare samples made: (m_X - m_Y)² / (var / n) (the pixel's
/// ordinary light, counted in m_X, made a highlight on a lit surface look like many samples).
/// Infinite (no claim) for a mean of 0 or below (a signed AOV).
double samples_of_mean(const RenderResult& a, const RenderResult& b, size_t i, int c) {
  const double va = variance_of_mean(a, i, c), vb = variance_of_mean(b, i, c);
  const bool x_is_a = va >= vb;
  const RenderResult &x = x_is_a ? a : b, &y = x_is_a ? b : a;
  const double vx = std::max(va, vb);
  const double mx = x.mean.rgb[i * 3 + c], my = y.mean.rgb[i * 3 + c];
  const auto per_sample = [](const RenderResult& r, size_t k, int ch) {
    return r.variance.rgb.empty() ? 0.0 : std::max(0.0, double(r.variance.rgb[k * 3 + ch]));
  };
  if (per_sample(y, i, c) < 0.1 * per_sample(x, i, c)) return (mx - my) * (mx - my) / vx;
  return mx > 0 ? mx * mx / vx : std::numeric_limits<double>::infinity();
}

/// The z score of a difference d with standard error sqrt(var_eps) (both standard errors and
/// the tolerance eps squared). With no error at all (variances 0 and eps = 0) the test is exact
/// equality: equal means score 0 (0/0 was NaN, which failed identical images), unequal ones
/// +-inf. A NaN difference stays NaN, and fails.
double z_score(double d, double var_eps) {
  if (var_eps == 0 && d == 0) return 0;
  return d / std::sqrt(var_eps);
}

/// The variance of image r's mean in channel c, from `pixels`, the sum of its pixels' variances
/// of the mean over N^2 (as if independent). With caustics (r.light_mean_variance) the light part
/// is correlated between pixels: its share of `pixels` is replaced by its variance from the light
/// paths' totals, so that the camera part counts per pixel and the light part once, as a whole.
double image_mean_variance(const RenderResult& r, double pixels, int c) {
  if (!r.light_mean_variance) return pixels;
  const LightMeanVariance& l = *r.light_mean_variance;
  // (the float variance layers round; a pixel of n < 2 counts 0 above, its light part too)
  return std::max(0.0, pixels - l.pixels[c]) + l.paths[c];
}

void check_layers(const RenderResult& r, const char* which) {
  // (a size of -1 x -3 counted 3 pixels through size_t, and 0 x 0 passed with nothing tested)
  if (r.mean.width <= 0 || r.mean.height <= 0)
    throw Error(std::string("compare: image ") + which + " has no pixels (" +
                std::to_string(r.mean.width) + "x" + std::to_string(r.mean.height) + ")");
  size_t npix = static_cast<size_t>(r.mean.width) * r.mean.height;
  if (r.mean.rgb.size() != npix * 3)
    throw Error(std::string("compare: image ") + which + " has inconsistent pixel data");
  if (!r.variance.rgb.empty() && r.variance.rgb.size() != npix * 3)
    throw Error(std::string("compare: image ") + which + " has a variance layer of the wrong size");
  if (!r.samples.empty() && r.samples.size() != npix)
    throw Error(std::string("compare: image ") + which +
                " has a sample-count layer of the wrong size");
}

}  // namespace

void check_comparable_image(const RenderResult& image, const std::string& path) {
  const int w = image.mean.width;
  // layers of the image's size first (a 0-wide image with an n layer divided by its width)
  const size_t npix = static_cast<size_t>(std::max(0, w)) * std::max(0, image.mean.height);
  if (w <= 0 || image.mean.height <= 0 || image.mean.rgb.size() != npix * 3 ||
      (!image.variance.rgb.empty() && image.variance.rgb.size() != npix * 3) ||
      (!image.samples.empty() && image.samples.size() != npix))
    throw Error(path + ": inconsistent image (no pixels, or layers of other sizes)");
  for (size_t i = 0; i < image.samples.size(); ++i)
    if (image.samples[i] == 0)
      throw Error(path + ": pixel (" + std::to_string(i % static_cast<size_t>(w)) + ", " +
                  std::to_string(i / static_cast<size_t>(w)) +
                  ") holds no samples (n = 0): its value is no estimate (an interrupted render, "
                  "or one whose samples were all non-finite)");
  const char* const names[2][3] = {{"R", "G", "B"}, {"var.R", "var.G", "var.B"}};
  const std::vector<float>* const planes[2] = {&image.mean.rgb, &image.variance.rgb};
  for (int p = 0; p < 2; ++p)
    for (size_t k = 0; k < planes[p]->size(); ++k) {
      const float v = (*planes[p])[k];
      // a variance is never negative (one was taken as 0)
      if (std::isfinite(v) && (p == 0 || v >= 0)) continue;
      const size_t i = k / 3;
      std::string what;
      if (std::isfinite(v)) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%g", double(v));
        what = std::string(" is negative (") + buf + ")";
      } else {
        what = std::string(" is not finite (") +
               (std::isnan(v) ? "nan"
                : v > 0       ? "inf"
                              : "-inf") +
               ")";
      }
      throw Error(path + ": pixel (" + std::to_string(i % static_cast<size_t>(w)) + ", " +
                  std::to_string(i / static_cast<size_t>(w)) + ") channel " + names[p][k % 3] +
                  what);
    }
}

CompareResult compare_images(const RenderResult& a, const RenderResult& b,
                             const CompareOptions& o) {
  // as the command line's ranges: an alpha of NaN or 2 made the threshold 0, and every
  // comparison passed. The value as it reads back (std::to_string's six decimals said "must be in
  // [0, 1], got 1.000000" of 1.0000001, and "got 0.000000" of an alpha of 1e-13)
  if (!(o.alpha >= 1e-12 && o.alpha <= 0.5))
    throw Error("compare: alpha must be in [1e-12, 0.5], got " +
                scene_detail::format_number(o.alpha));
  if (!(o.min_pass_fraction >= 0 && o.min_pass_fraction <= 1))
    throw Error("compare: min_pass_fraction must be in [0, 1], got " +
                scene_detail::format_number(o.min_pass_fraction));
  if (!(o.abs_epsilon >= 0) || !(o.rel_epsilon >= 0) || !std::isfinite(o.abs_epsilon) ||
      !std::isfinite(o.rel_epsilon))
    throw Error("compare: abs_epsilon and rel_epsilon must be finite and >= 0");
  if (a.mean.width != b.mean.width || a.mean.height != b.mean.height)
    throw Error("compare: image sizes differ: " + std::to_string(a.mean.width) + "x" +
                std::to_string(a.mean.height) + " and " + std::to_string(b.mean.width) + "x" +
                std::to_string(b.mean.height));
  check_layers(a, "A");
  check_layers(b, "B");
  CompareResult r;
  r.width = a.mean.width;
  r.height = a.mean.height;
  r.statistical = !a.variance.rgb.empty() || !b.variance.rgb.empty();
  const size_t npix = static_cast<size_t>(r.width) * r.height;
  r.tested = npix * 3;
  // Sidak: each of m tests at 1 - (1 - alpha)^(1/m)
  r.z = Image{r.width, r.height, std::vector<float>(npix * 3)};
  double per_test = -std::expm1(std::log1p(-o.alpha) / static_cast<double>(r.tested));
  r.z_threshold = normal_two_sided_critical(per_test);

  double sq = 0, rel = 0, sum_var_a[3] = {0, 0, 0}, sum_var_b[3] = {0, 0, 0};
  double largest_var[3] = {0, 0, 0};  // the pixel with the largest var_a + var_b, per channel
  size_t largest_at[3] = {0, 0, 0};
  const bool a_stats = !a.variance.rgb.empty(), b_stats = !b.variance.rgb.empty();
  for (size_t i = 0; i < npix; ++i) {
    bool pixel_ok = true;
    if ((a_stats && sample_count(a, i) < CompareResult::kFewPixelSamples) ||
        (b_stats && sample_count(b, i) < CompareResult::kFewPixelSamples))
      ++r.few_sample_pixels;
    for (int c = 0; c < 3; ++c) {
      double va = a.mean.rgb[i * 3 + c], vb = b.mean.rgb[i * 3 + c];
      double d = va - vb;
      const double var_a = variance_of_mean(a, i, c), var_b = variance_of_mean(b, i, c);
      double var = var_a + var_b;
      double eps = o.abs_epsilon + o.rel_epsilon * std::max(std::abs(va), std::abs(vb));
      const double pixel_var = pixel_test_variance(a, b, i, c);
      double z = z_score(d, pixel_var + eps * eps);
      r.z.rgb[i * 3 + c] = static_cast<float>(z);
      bool ok = std::isfinite(z) && std::abs(z) <= r.z_threshold;
      if (!ok) {
        ++r.failed_channels;
        pixel_ok = false;
        // no variance in either image there, the one with statistics at few samples: its
        // samples agreed, perhaps all missing what the pixel rarely sees, and nothing in the
        // other image can say so (a PFM reference; the same one as an EXR with variances passed)
        if (a_stats != b_stats && pixel_var == 0 &&
            sample_count(a_stats ? a : b, i) < CompareResult::kFewSamplesOfNoVariance)
          ++r.zero_variance_failures;
      }
      double az = std::isfinite(z) ? std::abs(z) : INFINITY;
      if (az > r.max_z || (i == 0 && c == 0)) {
        r.max_z = az;
        r.max_z_x = static_cast<int>(i % r.width);
        r.max_z_y = static_cast<int>(i / r.width);
        r.max_z_channel = c;
      }
      r.mean_a[c] += va;
      r.mean_b[c] += vb;
      sum_var_a[c] += var_a;
      sum_var_b[c] += var_b;
      if (var > largest_var[c]) {
        largest_var[c] = var;
        largest_at[c] = i;
      }
      sq += d * d;
      rel += d * d / (vb * vb + 0.01);
      r.max_abs_error = std::max(r.max_abs_error, std::isfinite(d) ? std::abs(d) : INFINITY);
    }
    if (!pixel_ok) ++r.failed_pixels;
  }
  const double n = static_cast<double>(npix);
  r.rmse = std::sqrt(sq / (3 * n));
  r.relmse = rel / (3 * n);
  r.pass_fraction = 1.0 - static_cast<double>(r.failed_pixels) / n;
  r.required_fraction = o.min_pass_fraction;

  r.mean_z_threshold = normal_two_sided_critical(-std::expm1(std::log1p(-o.alpha) / 3));
  r.mean_test_passed = true;
  r.light_paths_a = a.light_mean_variance.has_value();
  r.light_paths_b = b.light_mean_variance.has_value();
  for (int c = 0; c < 3; ++c) {
    r.mean_a[c] /= n;
    r.mean_b[c] /= n;
    double eps =
        o.abs_epsilon + o.rel_epsilon * std::max(std::abs(r.mean_a[c]), std::abs(r.mean_b[c]));
    const double var = image_mean_variance(a, sum_var_a[c] / (n * n), c) +
                       image_mean_variance(b, sum_var_b[c] / (n * n), c);
    r.mean_z[c] = z_score(r.mean_a[c] - r.mean_b[c], var + eps * eps);
    // the channel whose largest pixel share warns, or else the largest share (each channel
    // checked: a lamp in one channel hid a rare highlight in another)
    const double pixels_var = sum_var_a[c] + sum_var_b[c];
    if (pixels_var > 0) {
      const double share = largest_var[c] / pixels_var;
      const size_t i = largest_at[c];
      const double samples = samples_of_mean(a, b, i, c);
      const bool dominated =
          share > CompareResult::kDominatedShare && samples < CompareResult::kFewSamples;
      if (dominated != r.mean_variance_dominated() ? dominated : share > r.mean_variance_share) {
        r.mean_variance_share = share;
        r.mean_variance_x = static_cast<int>(i % r.width);
        r.mean_variance_y = static_cast<int>(i / r.width);
        r.mean_variance_channel = c;
        r.mean_variance_samples = samples;
      }
    }
    if (o.image_mean_test && !(std::abs(r.mean_z[c]) <= r.mean_z_threshold))
      r.mean_test_passed = false;
  }
  r.passed = r.pass_fraction >= o.min_pass_fraction && r.mean_test_passed;
  return r;
}

std::string CompareResult::summary() const {
  char buf[1024];
  std::string s;
  std::snprintf(buf, sizeof buf, "size          %dx%d (%s)\n", width, height,
                statistical ? "z-test with per-pixel variances" : "no variances: tolerance test");
  s += buf;
  std::snprintf(buf, sizeof buf, "mean A        %.6g %.6g %.6g\nmean B        %.6g %.6g %.6g\n",
                mean_a[0], mean_a[1], mean_a[2], mean_b[0], mean_b[1], mean_b[2]);
  s += buf;
  std::snprintf(buf, sizeof buf, "image-mean z  %.3f %.3f %.3f (threshold %.3f)%s\n", mean_z[0],
                mean_z[1], mean_z[2], mean_z_threshold, mean_test_passed ? "" : "  FAIL");
  s += buf;
  if (light_paths_a || light_paths_b) {
    s += "image-mean var camera part per pixel, light part from the light paths' totals in ";
    s += light_paths_a && light_paths_b ? "A and B\n"
         : light_paths_a ? "A (B's pixels taken as independent: no lucent.light_mean_var)\n"
                         : "B (A's pixels taken as independent: no lucent.light_mean_var)\n";
  }
  if (mean_variance_dominated()) {
    std::snprintf(buf, sizeof buf,
                  "warning       pixel (%d, %d) channel %c holds %.1f%% of the image means' "
                  "variance, and its mean rests on about %.1f samples: a rare, bright value "
                  "decides it (a heavy-tailed estimate), and the image-mean |z| stays near 1 "
                  "however far the means are; compare with more samples in both\n",
                  mean_variance_x, mean_variance_y, "RGB"[mean_variance_channel],
                  100 * mean_variance_share, mean_variance_samples);
    s += buf;
  }
  if (zero_variance_failures > 0) {
    std::snprintf(buf, sizeof buf,
                  "warning       %zu failing pixel-channels have no variance in either image: "
                  "the samples of the image with variances agreed there, from fewer than %g, "
                  "and may all have missed what the pixel rarely sees; compare against an image "
                  "with variances (an EXR lucent wrote), or with more samples\n",
                  zero_variance_failures, kFewSamplesOfNoVariance);
    s += buf;
  }
  if (few_sample_pixels > 0) {
    std::snprintf(buf, sizeof buf,
                  "warning       %zu of %d pixels rest on fewer than %g samples in an image: "
                  "their sample variances are unreliable, and correct renders fail the per-pixel "
                  "test more often than alpha says; compare with more samples\n",
                  few_sample_pixels, width * height, kFewPixelSamples);
    s += buf;
  }
  std::snprintf(buf, sizeof buf, "RMSE          %.6g\nrelMSE        %.6g\nmax abs error %.6g\n",
                rmse, relmse, max_abs_error);
  s += buf;
  std::snprintf(buf, sizeof buf, "max |z|       %.3f at (%d, %d) channel %c (threshold %.3f)\n",
                max_z, max_z_x, max_z_y, "RGB"[max_z_channel], z_threshold);
  s += buf;
  std::snprintf(buf, sizeof buf, "failed        %zu of %zu pixel-channels, %zu pixels\n",
                failed_channels, tested, failed_pixels);
  s += buf;
  std::snprintf(buf, sizeof buf, "pixels passed %.4f%% (required %.4f%%)\n", 100 * pass_fraction,
                100 * required_fraction);
  s += buf;
  s += passed ? "PASS\n" : "FAIL\n";
  return s;
}

}  // namespace lucent
