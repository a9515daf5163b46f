// The statistical image comparison (lucent/compare.hpp), the EXR layout with variance and sample
// counts, and `lucent compare`.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "image/image_probe.hpp"
#include "lucent/compare.hpp"
#include "lucent/reference.hpp"
#include "render/resources.hpp"
#include "support.hpp"

namespace test_compare {

namespace {

using lucent::CompareOptions;
using lucent::CompareResult;
using lucent::RenderResult;

// A small noisy scene: a diffuse sphere on a plane under a point light and an environment.
const char* kScene = R"({
  "camera": {"position": [0, 1, 5], "look_at": [0, 0.3, 0], "fov": 35},
  "film": {"width": 32, "height": 24},
  "integrator": {"type": "path", "max_depth": 4},
  "materials": {"a": {"type": "diffuse", "albedo": [0.7, 0.5, 0.3]},
                "b": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
  "shapes": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.8, "material": "a"},
             {"type": "sphere", "center": [0, -1000, 0], "radius": 999.7, "material": "b"}],
  "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [20, 20, 20]},
             {"type": "environment", "radiance": [0.3, 0.35, 0.4]}]
})";

RenderResult render_ref(std::uint32_t seed, int spp = 32) {
  lucent::Scene scene = lucent::test::scene_from(kScene);
  scene.integrator.seed = seed;
  lucent::ReferenceOptions o;
  o.spp = spp;
  return lucent::render_reference(scene, o);
}

RenderResult constant_image(int w, int h, float v) {
  RenderResult r;
  r.mean = lucent::Image{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3, v)};
  return r;
}

// Standard normal quantiles: P(|Z| > 1.959964) = 0.05, P(|Z| > 2.575829) = 0.01.
TEST(Compare, NormalCriticalValues) {
  EXPECT_NEAR(lucent::normal_two_sided_critical(0.05), 1.959964, 1e-5);
  EXPECT_NEAR(lucent::normal_two_sided_critical(0.01), 2.575829, 1e-5);
  EXPECT_NEAR(lucent::normal_two_sided_critical(1e-6), 4.891638, 1e-5);
  // the ends of [0, 1], and no probability (NaN gave 0, a threshold every difference passes)
  EXPECT_EQ(lucent::normal_two_sided_critical(1), 0);
  EXPECT_EQ(lucent::normal_two_sided_critical(0), INFINITY);
  EXPECT_EQ(lucent::test::error_of([] { lucent::normal_two_sided_critical(std::nan("")); }),
            "normal_two_sided_critical: p must be a probability in [0, 1], got nan");
  EXPECT_EQ(lucent::test::error_of([] { lucent::normal_two_sided_critical(1.5); }),
            "normal_two_sided_critical: p must be a probability in [0, 1], got 1.5");
  EXPECT_EQ(lucent::test::error_of([] { lucent::normal_two_sided_critical(-1e-300); }),
            "normal_two_sided_critical: p must be a probability in [0, 1], got -1e-300");
}

TEST(Compare, IdenticalImagesPass) {
  RenderResult a = render_ref(1);
  CompareResult c = lucent::compare_images(a, a);
  EXPECT_TRUE(c.passed) << c.summary();
  EXPECT_EQ(c.failed_channels, 0u);
  EXPECT_EQ(c.rmse, 0.0);
  EXPECT_EQ(c.max_abs_error, 0.0);
  EXPECT_TRUE(c.statistical);
}

// Two independent renders (different seeds) of the same scene have the same expected image: the
// test must pass (its false-alarm rate is alpha = 1%; these seeds are fixed), and their RMSE
// must be non-zero.
TEST(Compare, IndependentRendersOfTheSameScenePass) {
  RenderResult a = render_ref(1), b = render_ref(2);
  CompareResult c = lucent::compare_images(a, b);
  EXPECT_TRUE(c.passed) << c.summary();
  EXPECT_GT(c.rmse, 0.0);
  EXPECT_GT(c.max_z, 0.5);  // the noise is really there
}

// A 2% brightness change of the noisy pixels only (those with a variance) is a bias the
// image-mean test sees, although each pixel's noise hides it: with the mean test off, the
// per-pixel test alone lets it through.
TEST(Compare, SmallGlobalBiasFails) {
  RenderResult a = render_ref(1, 64), b = render_ref(2, 64);
  for (size_t i = 0; i < b.mean.rgb.size(); ++i)
    if (b.variance.rgb[i] > 0) b.mean.rgb[i] *= 1.02f;
  CompareResult c = lucent::compare_images(a, b);
  EXPECT_FALSE(c.passed) << c.summary();
  EXPECT_FALSE(c.mean_test_passed);
  CompareOptions o;
  o.image_mean_test = false;
  CompareResult per_pixel = lucent::compare_images(a, b, o);
  EXPECT_TRUE(per_pixel.passed) << per_pixel.summary();
}

/// A 32x32 render of `spp` samples per pixel of one estimator, computed here: each sample is
/// 0.1 + shift, plus 2 with probability 1/64 (a rare bright path), its mean, sample variance and
/// count per pixel as a renderer writes them.
RenderResult rare_paths(int spp, std::uint32_t seed, double shift = 0) {
  const int w = 32, h = 32;
  RenderResult r = constant_image(w, h, 0.0f);
  r.variance = r.mean;
  r.samples.assign(size_t(w) * h, std::uint32_t(spp));
  std::uint64_t state = 0x9e3779b97f4a7c15ull * (seed + 1);
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    int hits = 0;
    for (int k = 0; k < spp; ++k) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      hits += (state >> 40) % 64 == 0;
    }
    const double p = double(hits) / spp, mean = 0.1 + shift + 2 * p;
    const double var = 4 * p * (1 - p) * spp / (spp - 1);  // (n - 1 in the denominator)
    for (int c = 0; c < 3; ++c) {
      r.mean.rgb[i * 3 + c] = float(mean);
      r.variance.rgb[i * 3 + c] = float(var);
    }
  }
  r.spp = std::uint32_t(spp);
  return r;
}

// A render of few samples against a converged one of the same estimator: the pixels whose few
// samples all missed the rare value have a sample variance of 0 (here 60% of them), and with
// each image's own variances they failed (z about -16) at every try, where the docs promise a
// false alarm with probability alpha. Each pixel's variance is the larger of the two images'
// per-sample variances (compare_images); a bias of 15% of the pixels' means still fails.
TEST(Compare, FewSamplesAgainstManyOfTheSameEstimatorPass) {
  const RenderResult many = rare_paths(16384, 1);
  int passed = 0;
  for (std::uint32_t seed = 2; seed < 12; ++seed) {
    const CompareResult c = lucent::compare_images(rare_paths(32, seed), many);
    passed += c.passed;
    EXPECT_EQ(c.few_sample_pixels, 0u);
    EXPECT_LT(c.max_z, 6.0) << c.summary();
  }
  EXPECT_GE(passed, 9);
  const CompareResult biased = lucent::compare_images(rare_paths(32, 20, 0.02), many);
  EXPECT_FALSE(biased.passed) << biased.summary();
  EXPECT_FALSE(biased.mean_test_passed) << biased.summary();
  // an image without variances (a deterministic reference) still counts as exact: the pixels
  // whose samples all missed the rare value fail, and the summary says why they may have
  const CompareResult exact =
      lucent::compare_images(rare_paths(32, 3), constant_image(32, 32, 0.1f + 2.0f / 64));
  EXPECT_TRUE(exact.statistical);
  EXPECT_GT(exact.max_z, 10.0) << exact.summary();
  EXPECT_GT(exact.zero_variance_failures, 300u) << exact.summary();
  EXPECT_NE(exact.summary().find(" failing pixel-channels have no variance in either image: the "
                                 "samples of the image with variances agreed there, from fewer "
                                 "than 64,"),
            std::string::npos)
      << exact.summary();
  EXPECT_EQ(lucent::compare_images(rare_paths(32, 4), many).zero_variance_failures, 0u);
}

// A render of many samples keeps nearly its own variance: a kernel of 64 spp and variance 0.01
// against a reference of 4096 spp and variance 1, with a local bias of +-25% in 96 pixels that
// leaves the image mean as it was, fails the per-pixel test (taking the larger variance of the
// two, the first version of the fix, passed it: z 2 where each image's own gave 12.5).
TEST(Compare, ALowVarianceRenderKeepsItsPowerAgainstANoisyReference) {
  const int w = 32, h = 32;
  const auto image = [&](float variance, std::uint32_t n) {
    RenderResult r = constant_image(w, h, 1.0f);
    r.variance = constant_image(w, h, variance).mean;
    r.samples.assign(size_t(w) * h, n);
    r.spp = n;
    return r;
  };
  RenderResult kernel = image(0.01f, 64);
  const RenderResult reference = image(1.0f, 4096);
  for (int p = 0; p < 96; ++p)
    for (int c = 0; c < 3; ++c) kernel.mean.rgb[size_t(p * 10) * 3 + c] = p < 48 ? 1.25f : 0.75f;
  const CompareResult r = lucent::compare_images(kernel, reference);
  EXPECT_TRUE(r.mean_test_passed) << r.summary();
  EXPECT_FALSE(r.passed) << r.summary();
  EXPECT_EQ(r.failed_pixels, 96u) << r.summary();
  EXPECT_GT(r.max_z, 7.0) << r.summary();
}

// Pixels of fewer than 8 samples: their sample variances are unreliable (two correct renders of
// 2 samples per pixel failed at every try), and the summary says so.
TEST(Compare, FewSamplesPerPixelAreSaid) {
  const CompareResult c = lucent::compare_images(rare_paths(2, 1), rare_paths(2, 2));
  EXPECT_EQ(c.few_sample_pixels, 32u * 32u);
  EXPECT_NE(c.summary().find("warning       1024 of 1024 pixels rest on fewer than 8 samples in "
                             "an image: their sample variances are unreliable"),
            std::string::npos)
      << c.summary();
  const CompareResult enough = lucent::compare_images(rare_paths(8, 1), rare_paths(64, 2));
  EXPECT_EQ(enough.few_sample_pixels, 0u);
  EXPECT_EQ(enough.summary().find("rest on fewer"), std::string::npos);
}

// One rare, bright sample (a near-mirror's highlight of a point light, found by one sample of
// 64) decides the image means' variance: the image-mean |z| is then about 1 however far the means
// are, and the comparison passes. The summary says so and names the pixel; two ordinary renders
// get no warning.
TEST(Compare, AVarianceThatOnePixelDecidesIsReported) {
  const int w = 16, h = 16, n = 64;
  const auto image = [&](float value, float variance) {
    RenderResult r = constant_image(w, h, value);
    r.variance = lucent::Image{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3, variance)};
    r.samples.assign(static_cast<size_t>(w) * h, n);
    return r;
  };
  RenderResult a = image(1, 0.01f), b = image(1, 0.01f);
  // pixel (5, 3) of A: 63 samples of 1 and one of 1e4
  const double x = 1e4, mean = (63 + x) / n;
  const double variance = (63 * (1 - mean) * (1 - mean) + (x - mean) * (x - mean)) / (n - 1);
  for (int c = 0; c < 3; ++c) {
    a.mean.pixel(5, 3)[c] = static_cast<float>(mean);
    a.variance.pixel(5, 3)[c] = static_cast<float>(variance);
  }
  const CompareResult c = lucent::compare_images(a, b);
  EXPECT_GT(c.mean_a[0], 1.5 * c.mean_b[0]);
  EXPECT_NEAR(c.mean_z[0], 1.0, 0.01);  // the means' difference over its own sample's weight
  EXPECT_TRUE(c.passed);                // (what the warning is for)
  EXPECT_GT(c.mean_variance_share, 0.99);
  EXPECT_EQ(c.mean_variance_x, 5);
  EXPECT_EQ(c.mean_variance_y, 3);
  EXPECT_EQ(c.mean_variance_channel, 0);
  EXPECT_NEAR(c.mean_variance_samples, 1.0, 0.05);  // its mean is one sample of 1e4's
  EXPECT_TRUE(c.mean_variance_dominated());
  EXPECT_NE(c.summary().find("warning       pixel (5, 3) channel R holds 100.0% of the image "
                             "means' variance, and its mean rests on about 1.0 samples"),
            std::string::npos)
      << c.summary();
  // a pixel whose variance is real (a small lamp, a relative sd of 10 at 4096 samples) holds the
  // same share at any count, but its mean rests on many samples: no warning (the review's find:
  // the warning could not be cleared by more samples)
  // a rare value on a lit pixel: 63 samples of 5 and one of 100, where B's samples are all
  // about 5: the excess over B is one sample's (the pixel's own light made it look like 18)
  {
    RenderResult lit_a = image(1, 0.01f), lit_b = image(1, 0.01f);
    const double m = (63 * 5 + 100.0) / n;
    const double v = (63 * (5 - m) * (5 - m) + (100 - m) * (100 - m)) / (n - 1);
    for (int k = 0; k < 3; ++k) {
      lit_a.mean.pixel(5, 3)[k] = static_cast<float>(m);
      lit_a.variance.pixel(5, 3)[k] = static_cast<float>(v);
      lit_b.mean.pixel(5, 3)[k] = 5;
    }
    const CompareResult lit = lucent::compare_images(lit_a, lit_b);
    EXPECT_NEAR(lit.mean_variance_samples, 1.0, 0.1);
    EXPECT_TRUE(lit.mean_variance_dominated()) << lit.summary();
  }
  // each channel is looked at: a lamp in R (a larger share, many samples) hid a rare highlight
  // in B
  {
    RenderResult ch_a = image(1, 0.01f), ch_b = image(1, 0.01f);
    for (RenderResult* x : {&ch_a, &ch_b}) {
      for (size_t k = 2; k < x->variance.rgb.size(); k += 3) x->variance.rgb[k] = 10;
      x->mean.pixel(2, 2)[0] = 1000;
      x->variance.pixel(2, 2)[0] = 1e5;
    }
    ch_a.mean.pixel(5, 3)[2] = static_cast<float>(mean);
    ch_a.variance.pixel(5, 3)[2] = static_cast<float>(variance);
    const CompareResult ch = lucent::compare_images(ch_a, ch_b);
    EXPECT_TRUE(ch.mean_variance_dominated()) << ch.summary();
    EXPECT_EQ(ch.mean_variance_channel, 2);
    EXPECT_EQ(ch.mean_variance_x, 5);
  }
  for (RenderResult* x : {&a, &b}) x->samples.assign(static_cast<size_t>(w) * h, 4096);
  for (RenderResult* x : {&a, &b})  // (both see the lamp)
    for (int k = 0; k < 3; ++k) {
      x->mean.pixel(5, 3)[k] = 10;
      x->variance.pixel(5, 3)[k] = 1e4;
    }
  const CompareResult lamp = lucent::compare_images(a, b);
  EXPECT_GT(lamp.mean_variance_share, 0.9);
  EXPECT_NEAR(lamp.mean_variance_samples, 100.0 * 4096 / 1e4, 1e-3);
  EXPECT_FALSE(lamp.mean_variance_dominated());
  EXPECT_EQ(lamp.summary().find("warning"), std::string::npos) << lamp.summary();
  const CompareResult ordinary = lucent::compare_images(render_ref(1), render_ref(2));
  EXPECT_LT(ordinary.mean_variance_share, CompareResult::kDominatedShare);
  EXPECT_EQ(ordinary.summary().find("warning"), std::string::npos) << ordinary.summary();
}

// A localized error: a block of 4x4 pixels 50% too bright fails the per-pixel test there.
TEST(Compare, LocalErrorFailsPixels) {
  RenderResult a = render_ref(1, 64), b = render_ref(2, 64);
  for (int y = 8; y < 12; ++y)
    for (int x = 8; x < 12; ++x)
      for (int c = 0; c < 3; ++c) b.mean.pixel(x, y)[c] *= 1.5f;
  CompareOptions o;
  o.image_mean_test = false;
  CompareResult c = lucent::compare_images(a, b, o);
  EXPECT_FALSE(c.passed) << c.summary();
  EXPECT_GE(c.failed_pixels, 8u);
  EXPECT_LE(c.failed_pixels, 16u);
  EXPECT_GE(c.max_z_x, 8);
  EXPECT_LT(c.max_z_x, 12);
  // the z image shows where: strongly negative (A < B) inside the block
  EXPECT_LT(c.z.pixel(9, 9)[0], -c.z_threshold);
  EXPECT_GT(c.z.pixel(20, 20)[0], -c.z_threshold);
}

// Deterministic images (no variances) are compared by tolerance: abs_epsilon + rel_epsilon |v|
// scaled by the z threshold.
TEST(Compare, DeterministicImagesUseTheTolerance) {
  RenderResult a = constant_image(8, 8, 0.5f), b = constant_image(8, 8, 0.5f + 1e-6f),
               c = constant_image(8, 8, 0.51f);
  CompareResult r1 = lucent::compare_images(a, b);
  EXPECT_TRUE(r1.passed) << r1.summary();
  EXPECT_FALSE(r1.statistical);
  CompareResult r2 = lucent::compare_images(a, c);
  EXPECT_FALSE(r2.passed) << r2.summary();
  EXPECT_NEAR(r2.max_abs_error, 0.01, 1e-6);
  EXPECT_NEAR(r2.rmse, 0.01, 1e-6);
  EXPECT_NEAR(r2.relmse, 0.0001 / (0.51 * 0.51 + 0.01), 1e-8);
}

// With both epsilons 0, a pixel-channel of variance 0 is tested for exact equality
// (docs/compare.md, "Zero variances"): equal means score z = 0 and pass (0/0 was NaN, which
// failed identical images), unequal ones score +-inf and fail; the image mean likewise.
TEST(Compare, ZeroEpsilonsTestZeroVariancePixelsForEquality) {
  CompareOptions o;
  o.abs_epsilon = 0;
  o.rel_epsilon = 0;
  o.min_pass_fraction = 1.0;
  RenderResult a = constant_image(4, 3, 0.5f);
  // a variance layer, 0 except in pixel 0 (a constant sky beside a noisy pixel)
  a.variance = lucent::Image{4, 3, std::vector<float>(4 * 3 * 3, 0.0f)};
  a.samples.assign(4 * 3, 16);
  a.variance.rgb[0] = a.variance.rgb[1] = a.variance.rgb[2] = 0.04f;
  RenderResult b = a;
  b.mean.rgb[0] = 0.52f;  // within the noise of pixel 0
  CompareResult same = lucent::compare_images(a, a, o);
  EXPECT_TRUE(same.passed) << same.summary();
  EXPECT_EQ(same.failed_channels, 0u);
  EXPECT_EQ(same.max_z, 0.0);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(same.mean_z[c], 0.0);
  for (float z : same.z.rgb) EXPECT_EQ(z, 0.0f);
  CompareResult noisy = lucent::compare_images(a, b, o);
  EXPECT_TRUE(noisy.passed) << noisy.summary();
  EXPECT_EQ(noisy.failed_channels, 0u);
  EXPECT_TRUE(std::isfinite(noisy.mean_z[0]));
  // an exact difference in a zero-variance pixel fails, with an infinite z of its sign
  RenderResult c = a;
  c.mean.rgb[3 * 5 + 1] = 0.5f + 1e-6f;
  CompareResult diff = lucent::compare_images(a, c, o);
  EXPECT_FALSE(diff.passed);
  EXPECT_EQ(diff.failed_channels, 1u);
  EXPECT_EQ(diff.z.rgb[3 * 5 + 1], -INFINITY);
  EXPECT_TRUE(std::isinf(diff.max_z));
  // deterministic images (no variance layers): the same, for the image mean too
  RenderResult d = constant_image(4, 3, 0.25f), e = constant_image(4, 3, 0.25f);
  CompareResult det = lucent::compare_images(d, e, o);
  EXPECT_TRUE(det.passed) << det.summary();
  EXPECT_TRUE(det.mean_test_passed);
  for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(det.mean_z[ch], 0.0);
  e.mean.rgb[7] = 0.75f;
  CompareResult det2 = lucent::compare_images(d, e, o);
  EXPECT_FALSE(det2.passed);
  EXPECT_FALSE(det2.mean_test_passed);
  EXPECT_EQ(det2.mean_z[1], -INFINITY);
}

TEST(Compare, NonFiniteValuesFail) {
  RenderResult a = constant_image(4, 4, 1.0f), b = constant_image(4, 4, 1.0f);
  b.mean.rgb[5] = NAN;
  CompareOptions o;
  o.min_pass_fraction = 1.0;
  EXPECT_FALSE(lucent::compare_images(a, b, o).passed);
}

TEST(Compare, SizeMismatchIsAnError) {
  EXPECT_THROW(lucent::compare_images(constant_image(4, 4, 1), constant_image(4, 5, 1)),
               lucent::Error);
}

// write_render_exr / read_render keep mean, variance and sample counts exactly.
TEST(Compare, ExrRoundTripKeepsStatistics) {
  RenderResult a = render_ref(3, 8);
  a.samples[7] = 5;  // counts need not be equal
  std::string path = lucent::test::temp_dir() + "/a.exr";
  lucent::write_render_exr(path, a);
  RenderResult b = lucent::read_render(path);
  ASSERT_EQ(b.mean.width, a.mean.width);
  ASSERT_EQ(b.mean.height, a.mean.height);
  EXPECT_EQ(b.mean.rgb, a.mean.rgb);
  EXPECT_EQ(b.variance.rgb, a.variance.rgb);
  EXPECT_EQ(b.samples, a.samples);
  // and the general reader still reads its colour
  lucent::Image plain = lucent::read_image(path);
  EXPECT_EQ(plain.rgb, a.mean.rgb);
}

// Counts above 2^24 (merged parts reach them) come back exactly: the UINT channel was read
// through its float copy, which rounded 16777217 to 16777216 (and the image's spp with it) and
// refused the largest counts, 4294967295 rounding to 2^32, as invalid.
TEST(Compare, ExrRoundTripKeepsLargeSampleCounts) {
  RenderResult a;
  a.mean = lucent::Image{2, 2, std::vector<float>(12, 0.5f)};
  a.variance = lucent::Image{2, 2, std::vector<float>(12, 0.25f)};
  a.samples = {16777217u, 4294967295u, 123456789u, 1u};
  std::string path = lucent::test::temp_dir() + "/large-n.exr";
  lucent::write_render_exr(path, a);
  RenderResult b = lucent::read_render(path);
  EXPECT_EQ(b.samples, a.samples);
  EXPECT_EQ(b.spp, 4294967295u);
}

// `lucent render --reference -o x.exr` writes the statistics layers; `lucent compare` prints the
// metrics and exits 0 on PASS, 1 on FAIL; errors name the file.
TEST(Compare, CommandLine) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/s.json", kScene);
  auto r1 = lucent::test::run_cli("render --reference -q --spp 16 --seed 1 '" + dir +
                                  "/s.json' -o '" + dir + "/a.exr'");
  ASSERT_EQ(r1.status, 0) << r1.err;
  auto r2 = lucent::test::run_cli("render --reference -q --spp 16 --seed 2 '" + dir +
                                  "/s.json' -o '" + dir + "/b.exr'");
  ASSERT_EQ(r2.status, 0) << r2.err;
  RenderResult a = lucent::read_render(dir + "/a.exr");
  ASSERT_EQ(a.samples.size(), 32u * 24u);
  EXPECT_EQ(a.samples[0], 16u);
  EXPECT_FALSE(a.variance.rgb.empty());

  auto same = lucent::test::run_cli("compare '" + dir + "/a.exr' '" + dir + "/b.exr' --zmap '" +
                                    dir + "/z.pfm'");
  EXPECT_EQ(same.status, 0) << same.out << same.err;
  EXPECT_NE(same.out.find("PASS"), std::string::npos);
  EXPECT_NE(same.out.find("RMSE"), std::string::npos);
  EXPECT_NE(same.out.find("relMSE"), std::string::npos);
  EXPECT_NE(same.out.find("max abs error"), std::string::npos);
  EXPECT_EQ(lucent::read_image(dir + "/z.pfm").width, 32);

  RenderResult c = a;
  for (float& v : c.mean.rgb) v *= 1.2f;
  lucent::write_render_exr(dir + "/c.exr", c);
  auto differ = lucent::test::run_cli("compare '" + dir + "/a.exr' '" + dir + "/c.exr'");
  EXPECT_EQ(differ.status, 1);
  EXPECT_NE(differ.out.find("FAIL"), std::string::npos);

  auto missing = lucent::test::run_cli("compare '" + dir + "/a.exr' '" + dir + "/nope.exr'");
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("nope.exr"), std::string::npos);
  EXPECT_EQ(lucent::test::count_lines(missing.err), 1);
}

// Renders carry the key of their random numbers (seed, sampler) through write_render_exr and
// read_render: from the kernel (a session) and from the reference; a result made by hand has
// none, and writes none. A seed attribute that is not a number is a one-line error.
TEST(Compare, RendersKeepTheirSeedThroughExr) {
  std::string dir = lucent::test::temp_dir();
  lucent::Scene scene = lucent::test::scene_from(kScene);
  scene.integrator.seed = 77;
  scene.integrator.sampler = lucent::SamplerType::Independent;
  lucent::RenderOptions ko;
  ko.spp = 2;
  ko.specialize = false;  // the full kernel, which many tests share
  for (const RenderResult& r : {lucent::test::render(scene, ko), render_ref(77, 2)}) {
    EXPECT_EQ(r.seed, 77u) << r.device;
    lucent::write_render_exr(dir + "/r.exr", r);
    RenderResult back = lucent::read_render(dir + "/r.exr");
    EXPECT_EQ(back.seed, 77u) << r.device;
    EXPECT_EQ(back.sampler, r.sampler) << r.device;
  }
  EXPECT_EQ(lucent::test::render(scene, ko).sampler, "independent");
  EXPECT_EQ(render_ref(77, 2).sampler,  // kScene's own
            lucent::type_name(lucent::test::scene_from(kScene).integrator.sampler));
  lucent::write_render_exr(dir + "/c.exr", constant_image(3, 2, 1.0f));
  EXPECT_EQ(lucent::read_render(dir + "/c.exr").sampler, "");

  lucent::image_detail::ExrExtras extras;
  extras.attributes = {{"lucent.seed", "12x"}, {"lucent.sampler", "sobol"}};
  lucent::image_detail::write_render_exr(dir + "/bad.exr", constant_image(3, 2, 1.0f), extras);
  try {
    lucent::read_render(dir + "/bad.exr");
    ADD_FAILURE() << "a seed of '12x' was read";
  } catch (const lucent::Error& e) {
    EXPECT_EQ(std::string(e.what()), dir + "/bad.exr: attribute lucent.seed: invalid number '12x'");
  }
}

// Caustics renders carry the image mean's light part (RenderResult::light_mean_variance) through
// write_render_exr and read_render as the attribute lucent.light_mean_var, exactly (six doubles
// in %.17g): the kernel's, the reference's and one made by hand; a render without caustics has
// none and writes none. A malformed attribute is a one-line error naming the file.
TEST(Compare, LightMeanVarianceRoundTripsThroughExr) {
  std::string dir = lucent::test::temp_dir();
  lucent::Scene scene = lucent::test::scene_from(
      lucent::test::glass_lamp_box_scene(4, 3, R"({"type": "gaussian", "radius": 2})", 6));
  lucent::RenderOptions ko;
  ko.spp = 4;
  lucent::ReferenceOptions ro;
  ro.spp = 4;
  RenderResult made = constant_image(4, 3, 0.5f);
  made.variance = made.mean;
  made.samples.assign(12, 4);
  made.light_mean_variance = lucent::LightMeanVariance{{1.0 / 3, 2e-300, 0}, {0.1, 7e22, 1e-7}};
  for (const RenderResult& r :
       {lucent::test::render(scene, ko), lucent::render_reference(scene, ro), made}) {
    ASSERT_TRUE(r.light_mean_variance) << r.device;
    EXPECT_GT(r.light_mean_variance->paths[1], 0.0) << r.device;
    lucent::write_render_exr(dir + "/r.exr", r);
    RenderResult back = lucent::read_render(dir + "/r.exr");
    ASSERT_TRUE(back.light_mean_variance) << r.device;
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(back.light_mean_variance->paths[c], r.light_mean_variance->paths[c]) << r.device;
      EXPECT_EQ(back.light_mean_variance->pixels[c], r.light_mean_variance->pixels[c]) << r.device;
    }
  }
  scene.integrator.caustics = false;
  const RenderResult plain = lucent::test::render(scene, ko);
  EXPECT_FALSE(plain.light_mean_variance);
  lucent::write_render_exr(dir + "/p.exr", plain);
  EXPECT_FALSE(lucent::read_render(dir + "/p.exr").light_mean_variance);

  for (const std::string bad :
       {"1 2 3 4 5", "1 2 3 4 5 6 7", "1 2 3 4 5 x", "1 2 3 -4 5 6", "1 2 3 nan 5 6",
        "1 2 3 inf 5 6", "1,2,3,4,5,6", "", "1 2 3 4 5 6\n7"}) {
    lucent::image_detail::ExrExtras extras;
    extras.attributes = {{"lucent.light_mean_var", bad}};
    lucent::image_detail::write_render_exr(dir + "/bad.exr", made, extras);
    try {
      lucent::read_render(dir + "/bad.exr");
      ADD_FAILURE() << "lucent.light_mean_var '" << bad << "' was read";
    } catch (const lucent::Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(dir + "/bad.exr: attribute lucent.light_mean_var: expected 6 finite "
                                 "numbers >= 0",
                           0),
                0u)
          << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

// The image mean's variance with caustics: per image, the pixels' sum of var / n over N^2, less
// the light part's share of it (pixels), plus the light part from the paths' totals (paths); an
// image without light_mean_variance counts its pixels as independent, and the report says which.
TEST(Compare, ImageMeanVarianceTakesTheLightPartFromThePaths) {
  RenderResult a = constant_image(2, 1, 1.0f), b = constant_image(2, 1, 0.0f);
  for (RenderResult* r : {&a, &b}) {
    r->variance = constant_image(2, 1, 8.0f).mean;  // var / n = 2 per pixel: 4 / N^2 = 1
    r->samples = {4, 4};
  }
  CompareOptions o;
  o.abs_epsilon = o.rel_epsilon = 0;
  CompareResult plain = lucent::compare_images(a, b, o);
  EXPECT_DOUBLE_EQ(plain.mean_z[0], 1.0 / std::sqrt(2.0));
  EXPECT_FALSE(plain.light_paths_a || plain.light_paths_b);
  EXPECT_EQ(plain.summary().find("light paths"), std::string::npos);

  a.light_mean_variance = lucent::LightMeanVariance{{3, 3, 3}, {0.5, 0.5, 2}};
  CompareResult one = lucent::compare_images(a, b, o);
  // A: 1 - 0.5 + 3 = 3.5 (blue: 1 - 2 clamps at 0, + 3), B: 1
  EXPECT_DOUBLE_EQ(one.mean_z[0], 1.0 / std::sqrt(4.5));
  EXPECT_DOUBLE_EQ(one.mean_z[2], 1.0 / std::sqrt(4.0));
  EXPECT_TRUE(one.light_paths_a);
  EXPECT_FALSE(one.light_paths_b);
  EXPECT_NE(one.summary().find("light paths' totals in A (B's pixels taken as independent"),
            std::string::npos)
      << one.summary();

  b.light_mean_variance = lucent::LightMeanVariance{{0, 0, 0}, {1, 1, 1}};
  CompareResult both = lucent::compare_images(a, b, o);
  EXPECT_DOUBLE_EQ(both.mean_z[0], 1.0 / std::sqrt(3.5));
  EXPECT_NE(both.summary().find("light paths' totals in A and B"), std::string::npos);
}

// A display image (PNG: tone-mapped, encoded, clipped) against a linear render compares the
// display transform: refused in either order, one line naming the display image. Two display
// images stay comparable (a tolerance test without variances).
TEST(Compare, DisplayImageAgainstALinearOneIsRefused) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/s.json", kScene);
  for (const char* out : {"a.exr", "a.png"}) {
    // (the full kernel, which many tests share: a specialised one cost CI a cold kernel build)
    auto r = lucent::test::run_cli("render -q --no-specialize --spp 4 --seed 1 '" + dir +
                                   "/s.json' -o '" + dir + "/" + out + "'");
    ASSERT_EQ(r.status, 0) << r.err;
  }
  for (const std::string& args :
       {"'" + dir + "/a.exr' '" + dir + "/a.png'", "'" + dir + "/a.png' '" + dir + "/a.exr'"}) {
    auto c = lucent::test::run_cli("compare " + args);
    EXPECT_EQ(c.status, 1) << args;
    EXPECT_EQ(lucent::test::count_lines(c.err), 1) << c.err;
    EXPECT_NE(c.err.find(dir + "/a.png: a PNG image holds display values"), std::string::npos)
        << c.err;
    EXPECT_EQ(c.out.find("FAIL"), std::string::npos) << c.out;
  }
  auto same = lucent::test::run_cli("compare '" + dir + "/a.png' '" + dir + "/a.png'");
  EXPECT_EQ(same.status, 0) << same.out << same.err;
  EXPECT_NE(same.out.find("PASS"), std::string::npos);
}

// An input image holding a NaN or an infinity (a PFM can) is an error in that file, not a
// difference between renders: one line naming the file, the pixel and the channel, exit 1 as
// every error, and no PASS/FAIL report (it printed FAIL with "max |z| inf", as if the renders
// disagreed). A NaN in a variance layer too, and a negative variance.
TEST(Compare, NonFiniteInputIsAnInputError) {
  const std::string dir = lucent::test::temp_dir();
  lucent::Image img{8, 8, std::vector<float>(8 * 8 * 3, 0.5f)};
  lucent::write_image(dir + "/ok.pfm", img);
  img.rgb[(3 * 8 + 4) * 3 + 1] = NAN;
  lucent::write_image(dir + "/nan.pfm", img);
  RenderResult v = constant_image(8, 8, 0.5f);
  v.variance = lucent::Image{8, 8, std::vector<float>(8 * 8 * 3, 0.1f)};
  v.samples.assign(64, 16);
  v.variance.rgb[(7 * 8 + 7) * 3 + 2] = NAN;
  lucent::write_render_exr(dir + "/var.exr", v);
  // a negative variance (none is) was taken as 0
  v.variance.rgb[(7 * 8 + 7) * 3 + 2] = 0.1f;
  v.variance.rgb[(2 * 8 + 1) * 3 + 0] = -0.5f;
  lucent::write_render_exr(dir + "/neg.exr", v);
  const std::pair<std::string, std::string> cases[] = {
      {"nan.pfm nan.pfm", "nan.pfm: pixel (4, 3) channel G is not finite (nan)"},
      {"ok.pfm nan.pfm", "nan.pfm: pixel (4, 3) channel G is not finite (nan)"},
      {"var.exr ok.pfm", "var.exr: pixel (7, 7) channel var.B is not finite (nan)"},
      {"ok.pfm neg.exr", "neg.exr: pixel (1, 2) channel var.R is negative (-0.5)"}};
  for (const auto& [args, want] : cases) {
    const size_t space = args.find(' ');
    auto r = lucent::test::run_cli("compare '" + dir + "/" + args.substr(0, space) + "' '" + dir +
                                   "/" + args.substr(space + 1) + "' --zmap '" + dir + "/z.exr'");
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_EQ(r.err, "lucent: error: " + dir + "/" + want + "\n") << args;
    EXPECT_TRUE(r.out.empty()) << args << ": " << r.out;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/z.exr"));
  auto same = lucent::test::run_cli("compare '" + dir + "/ok.pfm' '" + dir + "/ok.pfm'");
  EXPECT_EQ(same.status, 0) << same.out << same.err;
}

// A pixel whose count (the n layer) is 0 holds no estimate: an interrupted reference's pixels
// after the one it stopped in, or a render whose every sample was non-finite. compare took its
// value for an exact black and passed such a render against a black one. Now an input error
// naming the file and the pixel, as for a NaN; converge's reference and Python's compare too.
TEST(Compare, PixelWithoutSamplesIsAnInputError) {
  const std::string dir = lucent::test::temp_dir();
  RenderResult black = constant_image(4, 4, 0.0f);
  black.variance = lucent::Image{4, 4, std::vector<float>(4 * 4 * 3, 0.0f)};
  black.samples.assign(16, 8);
  lucent::write_render_exr(dir + "/black.exr", black);
  RenderResult empty = black;
  empty.samples[2 * 4 + 3] = 0;
  lucent::write_render_exr(dir + "/empty.exr", empty);
  for (const std::string args : {"empty.exr black.exr", "black.exr empty.exr"}) {
    const size_t space = args.find(' ');
    auto r = lucent::test::run_cli("compare '" + dir + "/" + args.substr(0, space) + "' '" + dir +
                                   "/" + args.substr(space + 1) + "'");
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_EQ(r.err, "lucent: error: " + dir +
                         "/empty.exr: pixel (3, 2) holds no samples (n = 0): its value is no "
                         "estimate (an interrupted render, or one whose samples were all "
                         "non-finite)\n")
        << args;
  }
  auto same = lucent::test::run_cli("compare '" + dir + "/black.exr' '" + dir + "/black.exr'");
  EXPECT_EQ(same.status, 0) << same.out << same.err;
}

// Layers of other sizes, or no pixels, are an input error too (a 0-wide image with an n layer
// divided by its width: SIGFPE).
TEST(Compare, InconsistentLayersAreAnInputError) {
  RenderResult z;
  z.samples = {0};
  EXPECT_EQ(lucent::test::error_of([&] { lucent::check_comparable_image(z, "z"); }),
            "z: inconsistent image (no pixels, or layers of other sizes)");
  RenderResult short_n = constant_image(4, 4, 0.5f);
  short_n.samples.assign(15, 8);
  EXPECT_EQ(lucent::test::error_of([&] { lucent::check_comparable_image(short_n, "s"); }),
            "s: inconsistent image (no pixels, or layers of other sizes)");
  short_n.samples.assign(16, 8);
  EXPECT_EQ(lucent::test::error_of([&] { lucent::check_comparable_image(short_n, "s"); }), "");
  // options out of range (an alpha of NaN or 2 made the threshold 0: everything passed), and an
  // image of no pixels, which no reader took back
  lucent::CompareOptions o;
  for (double alpha : {std::nan(""), 2.0, 0.0}) {
    o.alpha = alpha;
    EXPECT_NE(lucent::test::error_of([&] {
                lucent::compare_images(short_n, short_n, o);
              }).find("compare: alpha must be in [1e-12, 0.5]"),
              std::string::npos)
        << alpha;
  }
  o = lucent::CompareOptions{};
  o.min_pass_fraction = 1.5;
  EXPECT_NE(lucent::test::error_of([&] {
              lucent::compare_images(short_n, short_n, o);
            }).find("min_pass_fraction must be in [0, 1]"),
            std::string::npos);
  // the value as it reads back: std::to_string said "got 1.000000" of 1.0000001 and "got
  // 0.000000" of an alpha of 1e-13 (the API tester's find)
  o.min_pass_fraction = 1.0000001;
  EXPECT_EQ(lucent::test::error_of([&] { lucent::compare_images(short_n, short_n, o); }),
            "compare: min_pass_fraction must be in [0, 1], got 1.0000001");
  o = lucent::CompareOptions{};
  o.alpha = 1e-13;
  EXPECT_EQ(lucent::test::error_of([&] { lucent::compare_images(short_n, short_n, o); }),
            "compare: alpha must be in [1e-12, 0.5], got 1e-13");
  const std::string dir = lucent::test::temp_dir();
  EXPECT_EQ(
      lucent::test::error_of([&] { lucent::write_render_exr(dir + "/e.exr", RenderResult{}); }),
      dir + "/e.exr: cannot write EXR: the image has no pixels");
  // images of no pixels, or of negative sizes, compared: -1 x -3 counted 3 pixels through size_t,
  // and 0 x 0 passed with nothing tested (the API tester's find)
  RenderResult odd;
  odd.mean = {-1, -3, std::vector<float>(9, 0.f)};
  EXPECT_EQ(lucent::test::error_of([&] { lucent::compare_images(odd, odd); }),
            "compare: image A has no pixels (-1x-3)");
  EXPECT_EQ(lucent::test::error_of([&] { lucent::compare_images(RenderResult{}, RenderResult{}); }),
            "compare: image A has no pixels (0x0)");
  // statistics layers of another size were left out of the file without a word; a light
  // variance that is not finite was written, and reading refused the file
  RenderResult layers = constant_image(2, 2, 0.5f);
  layers.variance = layers.mean;
  layers.samples = {4, 4, 4};
  EXPECT_EQ(lucent::test::error_of([&] { lucent::write_render_exr(dir + "/l.exr", layers); }),
            dir +
                "/l.exr: cannot write EXR: the variance layer has 12 values and the sample "
                "counts 3, where a 2x2 image has 12 and 4 (a variance needs the counts)");
  layers.samples.assign(4, 4);
  layers.light_mean_variance = lucent::LightMeanVariance{{std::nan(""), 0, 0}, {0, 0, 0}};
  EXPECT_NE(lucent::test::error_of([&] {
              lucent::write_render_exr(dir + "/l.exr", layers);
            }).find("l.exr: cannot write EXR: attribute lucent.light_mean_var: expected 6 finite"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir + "/l.exr"));
  layers.light_mean_variance.reset();
  lucent::write_render_exr(dir + "/l.exr", layers);
  EXPECT_EQ(lucent::read_render(dir + "/l.exr").samples.size(), 4u);
}

// The z map's path is checked before the images are read (a .txt z map was refused only after
// the comparison, and a PNG clipped the negative z values): the format, a directory that does
// not exist, an input.
// An image to compare is checked against the host's memory from its header, before it is
// decoded: two 16384x16384 PNGs took 9.4 GB, and past the host's memory the process is killed.
TEST(Compare, ReadingAnImageChecksItsMemoryFirst) {
  const std::string dir = lucent::test::temp_dir();
  lucent::write_image(dir + "/a.pfm", lucent::Image{64, 32, std::vector<float>(64 * 32 * 3, 0.5f)});
  ASSERT_EQ(lucent::read_render(dir + "/a.pfm").mean.width, 64);
  lucent::render_detail::DeviceLimits lim;
  lim.host_mem = 64 << 10;  // 64 KiB: less than 64 x 32 pixels at 32 bytes
  lucent::render_detail::ScopedLimitOverride o(lim);
  const std::string msg = lucent::test::error_of([&] { lucent::read_render(dir + "/a.pfm"); });
  EXPECT_EQ(msg.rfind(dir + "/a.pfm: reading this 64x32 image needs about 88.0 KiB of memory, " +
                          "more than the limit of 64.0 KiB (80% of ",
                      0),
            0u)
      << msg;
}

TEST(Compare, ZmapPathIsCheckedBeforeReading) {
  const std::string dir = lucent::test::temp_dir();
  const std::string images = " '" + dir + "/missing-a.exr' '" + dir + "/missing-b.exr' --zmap '";
  const std::pair<std::string, std::string> cases[] = {
      {"z.txt", "z.txt: unknown z map format '.txt' (use .exr or .pfm: z values are signed)"},
      {"z.png", "z.png: unknown z map format '.png' (use .exr or .pfm: z values are signed)"},
      {"no/such/dir/z.exr", "no/such/dir/z.exr: cannot write output (No such file or directory)"}};
  for (const auto& [zmap, want] : cases) {
    auto r = lucent::test::run_cli("compare" + images + dir + "/" + zmap + "'");
    EXPECT_EQ(r.status, 1) << zmap;
    EXPECT_EQ(r.err, "lucent: error: " + dir + "/" + want + "\n") << zmap;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

}  // namespace

}  // namespace test_compare
