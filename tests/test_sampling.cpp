// The samplers (kernels/shared/rng.h), adaptive sampling (Renderer::render_adaptive,
// render/adaptive.hpp) and clamping (integrator.clamp).
//
// Which sampler each test uses: the z-tests (kernel against reference, against analytic values,
// adaptive against uniform) use the independent sampler, whose per-pixel sample variance / n is
// the variance of the pixel's mean; the Sobol tests check the sampler's own properties (nets,
// direction numbers), that the kernel and the reference draw the same numbers, and that its
// error is lower, measured across seeds (each seed an independent scramble, so the spread of a
// pixel over seeds is the variance of its Sobol estimate, whatever the stratification).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <random>
#include <string>
#include <vector>

#include "cl/context.hpp"
#include "cl/kernel_source.hpp"
#include "lucent/compare.hpp"
#include "lucent/reference.hpp"
#include "lucent/session.hpp"
#include "probe_launch.hpp"
#include "render/adaptive.hpp"
#include "shared/rng.h"
#include "support.hpp"

namespace test_sampling {

namespace {

using lucent::RenderResult;
using lucent::SamplerType;
using lucent::Scene;

// ---- the Sobol sampler's numbers ------------------------------------------------------------

// The second Sobol dimension from its direction numbers (Joe and Kuo: polynomial x + 1, m_k =
// 2 m_{k-1} xor m_{k-1}, m_1 = 1), against the Pascal-matrix form of rng.h.
TEST(SobolSampler, SecondDimensionMatchesDirectionNumbers) {
  std::uint32_t v[32];
  std::uint32_t m = 1;
  for (int k = 1; k <= 32; ++k) {
    if (k > 1) m = (m << 1) ^ m;
    v[k - 1] = m << (32 - k);  // m_k / 2^k as a 32-bit fraction
  }
  for (std::uint32_t i = 0; i < (1u << 16); ++i) {
    std::uint32_t x = 0;
    for (int b = 0; b < 32; ++b)
      if (i >> b & 1u) x ^= v[b];
    ASSERT_EQ(lc_reverse_bits(lc_sobol1_reversed(i)), x) << "index " << i;
  }
}

// The first 2^k samples of a pixel's pair form a (0,k,2)-net: every elementary box of area 2^-k
// (2^a by 2^(k-a) cells) holds exactly one point; and every point is a different one as k grows
// (the first 2^k samples of 2^(k+1) are the first net).
TEST(SobolSampler, EveryPairOfEveryPixelIsANet) {
  for (std::uint32_t pixel : {0u, 7u, 123456u})
    for (std::uint32_t pair : {0u, 1u, 2u, 9u, 1000u})
      for (std::uint32_t seed : {0u, 42u})
        for (int k = 1; k <= 10; ++k) {
          const std::uint32_t n = 1u << k;
          std::vector<std::uint32_t> x(n), y(n);
          for (std::uint32_t s = 0; s < n; ++s) {
            lc_uint w[2];
            lc_sobol_pair(pixel, s, pair, seed, w);
            x[s] = w[0];
            y[s] = w[1];
          }
          for (int a = 0; a <= k; ++a) {
            std::vector<int> cells(n, 0);
            for (std::uint32_t s = 0; s < n; ++s) {
              const std::uint32_t cx = a ? x[s] >> (32 - a) : 0,
                                  cy = a < k ? y[s] >> (32 - (k - a)) : 0;
              ++cells[(cx << (k - a)) | cy];
            }
            ASSERT_EQ(*std::max_element(cells.begin(), cells.end()), 1)
                << "pixel " << pixel << " pair " << pair << " seed " << seed << " 2^" << a
                << " x 2^" << (k - a) << " boxes";
          }
        }
}

// Each number is uniform over pixels (the scrambles are random): the mean of one dimension of
// sample 0 over 2^16 pixels is 1/2 within 5 standard deviations (1 / sqrt(12 * 2^16)), and pairs
// and pixels are uncorrelated.
TEST(SobolSampler, UniformAndUncorrelatedOverPixels) {
  const int N = 1 << 16;
  for (std::uint32_t sample : {0u, 1u, 5u}) {
    double s0 = 0, s1 = 0, s01 = 0, sp = 0;
    for (int p = 0; p < N; ++p) {
      lc_uint a[2], b[2];
      lc_sobol_pair(static_cast<lc_uint>(p), sample, 3, 0, a);
      lc_sobol_pair(static_cast<lc_uint>(p), sample, 4, 0, b);
      const double u = lc_u01(a[0]) - 0.5, v = lc_u01(a[1]) - 0.5, w = lc_u01(b[0]) - 0.5;
      s0 += u;
      s1 += v;
      s01 += u * v;
      sp += u * w;
    }
    const double sd = 1 / std::sqrt(12.0 * N), sd_prod = 1 / (12.0 * std::sqrt(double(N)));
    EXPECT_LT(std::abs(s0 / N), 5 * sd);
    EXPECT_LT(std::abs(s1 / N), 5 * sd);
    EXPECT_LT(std::abs(s01 / N), 5 * sd_prod) << "the two numbers of a pair";
    EXPECT_LT(std::abs(sp / N), 5 * sd_prod) << "two pairs";
  }
}

// Numbers whose seeds or sample indices differ only in their top bits (a part's samples
// [2^31, 2^31 + n) against [0, n), seeds s and s + 2^31) are independent of each other: for both
// samplers, each of the first 16 dimensions, seeds and sample indices 0, 1, 2 and differences
// 2^28 .. 2^31 and 3 * 2^30, the top 4 bits of the two numbers over 2^14 pixels fall in the 16 x
// 16 cells of their joint table uniformly: Pearson's chi-square (255 degrees of freedom, 64
// expected per cell) below 413, 7 standard deviations above its mean (Wilson-Hilferty: p = 1.5e-9
// per table, 1.5e-6 for all 960; measured: at most 326). Before the inputs were folded (rng.h,
// LC_FOLD) pcg4d left them related: chi-square up to 2.5e5 (the independent sampler's dimension 4
// of sample 0 at seeds s and s + 2^31: one number's top 4 bits a function of the other's), 1.8e4
// for the Sobol keys' odd pairs at seeds 2^31 apart.
TEST(SamplerNumbers, IndependentWhenInputsDifferInTheirTopBits) {
  const std::uint32_t N = 1u << 14;
  for (bool sobol : {true, false})
    for (int word : {1, 3})  // the sample index, the seed
      for (std::uint32_t delta : {1u << 28, 1u << 29, 1u << 30, 1u << 31, 3u << 30})
        for (std::uint32_t base : {0u, 1u, 2u})
          for (std::uint32_t dim = 0; dim < 16; ++dim) {
            std::vector<double> cells(256, 0.0);
            for (std::uint32_t p = 0; p < N; ++p) {
              std::uint32_t top[2];
              for (int k = 0; k < 2; ++k) {
                const std::uint32_t add = k ? delta : 0u;
                const std::uint32_t sample = base + (word == 1 ? add : 0u);
                const std::uint32_t seed = base + (word == 3 ? add : 0u);
                lc_uint w[2];
                if (sobol)
                  lc_sobol_pair(p, sample, dim >> 1, seed, w);
                else
                  lc_independent_pair(p, sample, dim >> 1, seed, w);
                top[k] = w[dim & 1u] >> 28;
              }
              cells[top[0] * 16 + top[1]] += 1;
            }
            const double expected = N / 256.0;
            double chi2 = 0;
            for (double c : cells) chi2 += (c - expected) * (c - expected) / expected;
            ASSERT_LT(chi2, 413.0)
                << (sobol ? "sobol" : "independent") << ": " << (word == 1 ? "samples " : "seeds ")
                << base << " and " << base << " + " << delta << ", dimension " << dim;
          }
}

// ---- kernel and reference draw the same numbers ------------------------------------------------

const char* kLampScene = R"({
  "camera": {"position": [0, 1.5, 4], "look_at": [0, 0.3, 0], "fov": 40},
  "film": {"width": 32, "height": 32, "filter": {"type": "tent", "radius": 1}},
  "integrator": {"type": "path", "max_depth": 2, "sampler": "SAMPLER"},
  "materials": {"floor": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]},
                "ball": {"type": "diffuse", "albedo": [0.8, 0.3, 0.2]},
                "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [8, 7, 6]}},
  "shapes": [{"type": "triangles", "material": "floor",
              "positions": [[-5,0,-5],[5,0,-5],[5,0,5],[-5,0,5]], "indices": [0,2,1, 0,3,2]},
             {"type": "sphere", "center": [0.3, 0.5, 0], "radius": 0.5, "material": "ball"},
             {"type": "sphere", "center": [-0.8, 1.6, 0.6], "radius": 0.35, "material": "lamp"}]
})";

/// The same with a quad lamp (sampled uniformly by area in both the kernel and the reference,
/// where the sphere lamp is sampled by its cone in the kernel and by area in the reference) and
/// the box filter (the reference's tent filter draws extra numbers).
std::string quad_lamp_json() {
  std::string json = kLampScene;
  auto replace = [&](const std::string& from, const std::string& to) {
    json.replace(json.find(from), from.size(), to);
  };
  replace(R"(, "filter": {"type": "tent", "radius": 1})", "");
  replace(R"({"type": "sphere", "center": [-0.8, 1.6, 0.6], "radius": 0.35, "material": "lamp"})",
          R"({"type": "triangles", "material": "lamp",
              "positions": [[-1.2,2,0.2],[-0.4,2,0.2],[-0.4,2,1],[-1.2,2,1]], "indices": [0,1,2, 0,2,3]})");
  return json;
}

Scene scene_with(std::string json, SamplerType sampler) {
  json.replace(json.find("SAMPLER"), 7, sampler == SamplerType::Sobol ? "sobol" : "independent");
  return lucent::test::scene_from(json);
}

Scene lamp_scene(SamplerType sampler) { return scene_with(kLampScene, sampler); }

/// Whether pixel i of a and b agree within 1e-3 relative (+ 1e-4 absolute) in every channel.
bool pixel_equal(const RenderResult& a, const RenderResult& b, size_t i) {
  bool ok = true;
  for (int c = 0; c < 3; ++c) {
    const double x = a.mean.rgb[i * 3 + c], y = b.mean.rgb[i * 3 + c];
    ok = ok && std::abs(x - y) <= 1e-3 * std::abs(y) + 1e-4;
  }
  return ok;
}

// With the same seed the kernel and the reference trace the same camera rays and sample the same
// light points and directions, so at 1 spp (where every pixel is one noisy sample) their images
// agree pixel for pixel up to float rounding; with another seed they do not (the control).
TEST(SobolSampler, KernelAndReferenceDrawTheSameNumbers) {
  for (SamplerType t : {SamplerType::Sobol, SamplerType::Independent}) {
    SCOPED_TRACE(lucent::type_name(t));
    Scene s = scene_with(quad_lamp_json(), t);
    lucent::RenderOptions ko;
    ko.spp = 1;
    RenderResult k = lucent::test::render(s, ko);
    Scene other = s;
    other.integrator.seed = 1;
    RenderResult k_other = lucent::test::render(other, ko);
    lucent::ReferenceOptions ro;
    ro.spp = 1;
    RenderResult ref = lucent::render_reference(s, ro);
    RenderResult ref_other = lucent::render_reference(other, ro);
    // the pixels whose value depends on the random numbers (the seeds give different values)
    size_t noisy = 0, same = 0, same_control = 0;
    for (size_t i = 0; i < k.samples.size(); ++i) {
      if (pixel_equal(k, k_other, i)) continue;
      ++noisy;
      same += pixel_equal(k, ref, i);
      same_control += pixel_equal(k, ref_other, i);
    }
    ASSERT_GT(noisy, k.samples.size() / 2);
    EXPECT_GT(double(same) / noisy, 0.95) << same << " of " << noisy;
    EXPECT_LT(double(same_control) / noisy, 0.05) << same_control << " of " << noisy;
  }
}

// The megakernel's lc_rand8 (the Sobol sampler's four pairs computed in vector lanes) and lc_rand2,
// through a probe kernel, against rng.h's scalar lc_sobol_pair and lc_independent_quad: equal bit
// for bit on random and extreme pixels, samples, dimensions and seeds.
TEST(SobolSampler, KernelVectorNumbersEqualTheScalarOnes) {
  lucent::cl_util::Context ctx{lucent::test::device()};
  cl::Program program = lucent::cl_util::build_program(
      ctx, lucent::detail::assemble_kernel_source("test/rng_probe.cl", lucent::test::kernel_dir()),
      "-cl-std=CL1.2 -D LC_HAS_SAMPLER_SOBOL -D LC_HAS_SAMPLER_INDEPENDENT");
  std::vector<cl_uint4> query;
  std::mt19937 gen(7);
  for (int i = 0; i < 4096; ++i) {
    const cl_uint dim = (i % 16 == 0) ? 0xfffffff8u - 4u * (i % 5) : 4u * (gen() % 64u);
    query.push_back({{static_cast<cl_uint>(gen()), static_cast<cl_uint>(i % 3 == 0 ? i : gen()),
                      i % 7 == 0 ? LC_DIM_LIGHT_PATH + 8u * (i % 9) : dim,
                      static_cast<cl_uint>(i % 2 ? gen() : 0u)}});
  }
  query.push_back({{0u, 0u, 0u, 0u}});
  query.push_back({{0xffffffffu, 0xffffffffu, 0xfffffffcu, 0xffffffffu}});
  for (SamplerType t : {SamplerType::Sobol, SamplerType::Independent}) {
    SCOPED_TRACE(lucent::type_name(t));
    cl::Buffer b_query(ctx.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                       query.size() * sizeof(cl_uint4), query.data());
    cl::Buffer b_out(ctx.context, CL_MEM_WRITE_ONLY, query.size() * 10 * sizeof(float));
    cl::Kernel k(program, "probe_rng");
    const cl_uint sampler = t == SamplerType::Sobol ? LC_SAMPLER_SOBOL : LC_SAMPLER_INDEPENDENT;
    lucent::test::set_args(k, 0, b_query, sampler, b_out);
    lucent::test::launch_probe(ctx.queue, k, query.size());
    std::vector<float> out = lucent::test::read_back<float>(ctx.queue, b_out, query.size() * 10);
    size_t wrong = 0;
    for (size_t i = 0; i < query.size(); ++i) {
      const cl_uint4& q = query[i];
      lc_uint w[8];
      for (lc_uint g = 0; g < (t == SamplerType::Sobol ? 4u : 2u); ++g) {
        if (t == SamplerType::Sobol)
          lc_sobol_pair(q.s[0], q.s[1], (q.s[2] >> 1) + g, q.s[3], w + 2 * g);
        else
          lc_independent_quad(q.s[0], q.s[1], (q.s[2] >> 2) + g, q.s[3], w + 4 * g);
      }
      for (int d = 0; d < 10; ++d) {
        const float expected = lc_u01(w[d < 8 ? d : d - 8]);
        if (out[10 * i + d] != expected && wrong++ < 5)
          ADD_FAILURE() << "pixel " << q.s[0] << " sample " << q.s[1] << " dimension "
                        << q.s[2] + (d < 8 ? d : d - 8) << " seed " << q.s[3] << ": kernel "
                        << out[10 * i + d] << ", rng.h " << expected;
      }
    }
    EXPECT_EQ(wrong, 0u);
  }
}

// ---- the Sobol sampler's error ---------------------------------------------------------------

/// Mean over pixel-channels of the variance of the pixel over `seeds` renders, relative as relMSE
/// weighs errors (divided by mean^2 + 0.01).
double spread_over_seeds(Scene s, int spp, int seeds) {
  const size_t n = static_cast<size_t>(s.film.width) * s.film.height * 3;
  std::vector<double> sum(n, 0.0), sumsq(n, 0.0);
  lucent::RenderOptions o;
  o.spp = spp;
  for (int k = 0; k < seeds; ++k) {
    s.integrator.seed = 1000u + static_cast<std::uint32_t>(k);
    RenderResult r = lucent::test::render(s, o);
    for (size_t i = 0; i < n; ++i) {
      sum[i] += r.mean.rgb[i];
      sumsq[i] += double(r.mean.rgb[i]) * r.mean.rgb[i];
    }
  }
  double total = 0;
  for (size_t i = 0; i < n; ++i) {
    const double m = sum[i] / seeds, v = (sumsq[i] - sum[i] * m) / (seeds - 1);
    total += std::max(0.0, v) / (m * m + 0.01);
  }
  return total / double(n);
}

// Direct and one-bounce light from a sphere lamp: at 64 spp the Sobol sampler's relative variance
// is below half the independent sampler's (measured: about a fifth). 12 seeds: the ratio of two
// means over 3072 pixel-channels of 11-degree-of-freedom variances is known to a few percent.
TEST(SobolSampler, LowerErrorThanIndependentSamples) {
  const double sobol = spread_over_seeds(lamp_scene(SamplerType::Sobol), 64, 12);
  const double indep = spread_over_seeds(lamp_scene(SamplerType::Independent), 64, 12);
  RecordProperty("ratio", std::to_string(sobol / indep));
  EXPECT_LT(sobol, 0.5 * indep) << "sobol " << sobol << ", independent " << indep;
  EXPECT_GT(sobol, 0.0);
}

// ---- adaptive sampling -----------------------------------------------------------------------

TEST(AdaptivePlan, CountsFollowTheSquareRootOfTheVarianceAndMeetTheTarget) {
  const int W = 8, H = 8;
  std::vector<double> v(W * H, 0.01);
  for (int x = 0; x < W; ++x) v[3 * W + x] = 1.0;  // a noisy row
  auto p = lucent::render_detail::plan_samples(v, W, H, 1e-3, 0, 4, 1u << 20);
  EXPECT_LE(p.predicted, 1e-3);
  // the prediction is conservative: the variances raised to their 3 x 3 means, so at least v / n
  double check = 0;
  for (int i = 0; i < W * H; ++i) check += v[i] / p.counts[i];
  EXPECT_LE(check / (W * H), p.predicted);
  // far from the noisy row (and its 3 x 3 neighbourhood) counts are ~sqrt(100) = 10 times fewer
  const double ratio = double(p.counts[3 * W + 4]) / p.counts[7 * W + 4];
  EXPECT_NEAR(ratio, 10.0, 0.5);
  // a lower target never takes samples away; a budget is met
  auto q = lucent::render_detail::plan_samples(v, W, H, 5e-4, 0, 4, 1u << 20);
  for (int i = 0; i < W * H; ++i) EXPECT_GE(q.counts[i], p.counts[i]);
  auto b = lucent::render_detail::plan_samples(v, W, H, 0, 100, 4, 1u << 20);
  EXPECT_LE(b.mean, 100);
  EXPECT_GT(b.mean, 95);
}

TEST(AdaptivePlan, CombinedVarianceIsThatOfTheAverageOfTheHalves) {
  // half A: 2 samples {1, 3}; half B: 4 samples {2, 2, 4, 4}
  const double sa[3] = {4, 4, 4}, qa[3] = {10, 10, 10}, sb[3] = {12, 12, 12}, qb[3] = {40, 40, 40};
  float mean[3], var[3];
  std::uint32_t n;
  double half_var[2][3];
  lucent::render_detail::combine_halves(sa, qa, 2, sb, qb, 4, mean, var, &n, half_var);
  EXPECT_EQ(n, 6u);
  EXPECT_FLOAT_EQ(mean[0], 2.5f);  // (2 + 3) / 2, not the pooled 16 / 6
  // each half's own s^2 (not one pooled over both, (2 + 4) / (6 - 2) = 1.5: a half's count is
  // planned from the other half's pilot, which a pooled s^2 would read): s_A^2 = 2, s_B^2 = 4/3;
  // var(mean) = (s_A^2 / 2 + s_B^2 / 4) / 4; var = n var(mean)
  EXPECT_DOUBLE_EQ(half_var[0][0], 1.0);
  EXPECT_DOUBLE_EQ(half_var[1][0], 1.0 / 3);
  EXPECT_FLOAT_EQ(var[0] / 6, static_cast<float>((1.0 + 1.0 / 3) / 4));
  // one sample per half, {1} and {3} (a render stopped by --time in its pilot): their variance,
  // s^2 = (1 - 2)^2 + (3 - 2)^2 = 2 over 1 degree of freedom, not 0 (every pixel exact)
  const double s1[3] = {1, 1, 1}, q1[3] = {1, 1, 1}, s3[3] = {3, 3, 3}, q3[3] = {9, 9, 9};
  lucent::render_detail::combine_halves(s1, q1, 1, s3, q3, 1, mean, var, &n);
  EXPECT_EQ(n, 2u);
  EXPECT_FLOAT_EQ(mean[0], 2.0f);
  EXPECT_FLOAT_EQ(var[0] / 2, static_cast<float>(2.0 * (1.0 + 1.0) / 4));
}

/// Pilot sums of one pixel: `values` as samples in all 3 channels.
void add_pixel(lucent::render_detail::Pilot& p, std::initializer_list<double> values) {
  double sum = 0, sumsq = 0;
  for (double x : values) {
    sum += x;
    sumsq += x * x;
  }
  for (int c = 0; c < 3; ++c) {
    p.sum.push_back(sum);
    p.sumsq.push_back(sumsq);
  }
  p.count.push_back(static_cast<std::uint32_t>(values.size()));
}

// The gain's arithmetic on one pixel: O = {1, 3}, C = {2, 4}: (mean_O - mean_C)^2 / 2 = 1/2; the
// pooled variance of one sample (2 + 2) / 2 = 2, the model's variance of a 2-sample mean 2 / 2 =
// 1; both weighted by 1 / (2.5^2 + 0.01), which cancels: gain 1/2. Pixels with fewer than 2
// samples in O or C are left out; the gain is clamped.
TEST(AdaptivePlan, CalibrationGainOfAnAnalyticPilot) {
  using lucent::render_detail::calibrate_model;
  lucent::render_detail::Pilot o, c;
  add_pixel(o, {1, 3});
  add_pixel(c, {2, 4});
  add_pixel(o, {5});  // one sample: no variance, left out
  add_pixel(c, {50, 70});
  auto cal = calibrate_model(o.sum, o.sumsq, o.count, c.sum, c.sumsq, c.count);
  EXPECT_EQ(cal.pixels, 1u);
  EXPECT_DOUBLE_EQ(cal.measured, 3 * 0.5 / (6.25 + 0.01));
  EXPECT_DOUBLE_EQ(cal.modelled, 3 * 1.0 / (6.25 + 0.01));
  EXPECT_DOUBLE_EQ(cal.gain, 0.5);
  // equal means: measured 0, clamped to the lowest gain; far apart: to the highest
  lucent::render_detail::Pilot same;
  add_pixel(same, {3, 1});
  EXPECT_DOUBLE_EQ(calibrate_model(o.sum, o.sumsq, o.count, same.sum, same.sumsq, same.count).gain,
                   1.0 / 64);
  lucent::render_detail::Pilot far;
  add_pixel(far, {101, 103});
  EXPECT_DOUBLE_EQ(calibrate_model(o.sum, o.sumsq, o.count, far.sum, far.sumsq, far.count).gain,
                   4.0);
}

// The gain measures what it should, on simulated pilots of m = 4 samples of f(u) = u per pixel
// (20000 pixels, values near 0.5). The gain is V / (E[s^2] / m), V the variance of the pilot's
// mean and s^2 the sample variance the model reads, E[s^2] = m (sigma^2 - V) / (m - 1) for
// samples that are each uniform (sigma^2 = 1/12). Independent uniform samples: V = sigma^2 / m,
// gain 1. Jittered ones (one uniform sample in each quarter of [0, 1), a stratified sampler's
// faster convergence): V = m (1/m)^2 (1/12) / m^2 = 1/768, E[s^2] = (4/3) (1/12 - 1/768) =
// 0.109375, gain 1/21. The ratio of two sums of 20000 terms each is known to a few percent:
// tolerance 10%.
TEST(AdaptivePlan, CalibrationGainIsOneForIndependentSamplesAndLowerForStratified) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(0, 1);
  for (bool jittered : {false, true}) {
    lucent::render_detail::Pilot o, c;
    for (int p = 0; p < 20000; ++p)
      for (lucent::render_detail::Pilot* q : {&o, &c}) {
        double u[4];
        for (int k = 0; k < 4; ++k) u[k] = jittered ? (k + uniform(rng)) / 4 : uniform(rng);
        add_pixel(*q, {u[0], u[1], u[2], u[3]});
      }
    auto cal =
        lucent::render_detail::calibrate_model(o.sum, o.sumsq, o.count, c.sum, c.sumsq, c.count);
    EXPECT_NEAR(cal.gain, jittered ? 1.0 / 21 : 1.0, jittered ? 0.1 / 21 : 0.1)
        << (jittered ? "jittered" : "independent");
  }
}

// The gain scales the plan's prediction: the plan for target T with gain g is the plan for T / g
// with gain 1, and a gain below 1 plans fewer samples.
TEST(AdaptivePlan, GainScalesThePrediction) {
  const int W = 8, H = 8;
  std::vector<double> v(W * H, 0.01);
  for (int x = 0; x < W; ++x) v[3 * W + x] = 1.0;
  auto g = lucent::render_detail::plan_samples(v, W, H, 1e-3, 0, 4, 1u << 20, 0.25);
  auto one = lucent::render_detail::plan_samples(v, W, H, 4e-3, 0, 4, 1u << 20, 1);
  auto full = lucent::render_detail::plan_samples(v, W, H, 1e-3, 0, 4, 1u << 20, 1);
  EXPECT_EQ(g.counts, one.counts);
  EXPECT_DOUBLE_EQ(g.predicted, 0.25 * one.predicted);
  EXPECT_LE(g.predicted, 1e-3);
  EXPECT_LT(g.mean, 0.3 * full.mean);
  // a budget's plan ignores the gain
  EXPECT_EQ(lucent::render_detail::plan_samples(v, W, H, 0, 50, 4, 1u << 20, 0.25).counts,
            lucent::render_detail::plan_samples(v, W, H, 0, 50, 4, 1u << 20, 1).counts);
}

// Caustics' light term (adaptive.hpp): the prediction adds light_w / (sum of the counts), exactly;
// a light term only raises counts (the target is met with more samples); with no camera variance
// at all the counts are even and the target is met by the light term's total alone. The
// prediction stays monotone: a lower target never lowers a count.
TEST(AdaptivePlan, LightTermAddsToThePrediction) {
  using lucent::render_detail::plan_samples;
  const int W = 8, H = 8;
  std::vector<double> v(W * H, 0.01);
  for (int x = 0; x < W; ++x) v[3 * W + x] = 1.0;
  auto camera = plan_samples(v, W, H, 1e-3, 0, 4, 1u << 20, 1);
  auto light = plan_samples(v, W, H, 1e-3, 0, 4, 1u << 20, 1, 50.0);
  double total = 0;
  for (std::uint32_t n : light.counts) total += n;
  EXPECT_DOUBLE_EQ(light.light, 50.0 / total);
  EXPECT_LE(light.predicted, 1e-3);
  EXPECT_GT(light.predicted, light.light);
  EXPECT_GT(light.mean, camera.mean);
  for (size_t i = 0; i < v.size(); ++i) EXPECT_GE(light.counts[i], camera.counts[i]) << i;
  auto lower = plan_samples(v, W, H, 5e-4, 0, 4, 1u << 20, 1, 50.0);
  for (size_t i = 0; i < v.size(); ++i) EXPECT_GE(lower.counts[i], light.counts[i]) << i;
  // light only: even counts, the smallest total with 50 / total <= 1e-3, i.e. 50000 / 64 each
  auto only = plan_samples(std::vector<double>(W * H, 0.0), W, H, 1e-3, 0, 4, 1u << 20, 1, 50.0);
  EXPECT_EQ(*std::min_element(only.counts.begin(), only.counts.end()),
            *std::max_element(only.counts.begin(), only.counts.end()));
  EXPECT_EQ(only.counts[0], 782u);  // ceil(50000 / 64)
  EXPECT_LE(only.predicted, 1e-3);
  // unreachable with max_n: every count at max_n, the prediction over the target
  auto capped = plan_samples(v, W, H, 1e-3, 0, 4, 64, 1, 50.0);
  for (std::uint32_t n : capped.counts) EXPECT_EQ(n, 64u);
  EXPECT_GT(capped.predicted, 1e-3);
}

// add_light_halves: the light part is the average of the halves' light means (sum / paths), its
// variance that of the average, (s_A^2 / N_A + s_B^2 / N_B) / 4 with s^2 the unbiased variance
// of one path, added to var times n; one half's alone when the other traced no path.
TEST(AdaptivePlan, LightHalvesCombine) {
  // half A: 4 paths splatting 1, 3, 0, 0 in channel 0; half B: 2 paths, 2 and 0
  const double la[3] = {4, 0, 0}, qa[3] = {10, 0, 0}, lb[3] = {2, 0, 0}, qb[3] = {4, 0, 0};
  float mean[3] = {1, 1, 1}, var[3] = {0.5f, 0.5f, 0.5f};
  double lv[3];
  lucent::render_detail::add_light_halves(la, qa, 4, lb, qb, 2, 8, mean, var, lv);
  // A: mean 1, s^2 = (10 - 16 / 4) / 3 = 2; B: mean 1, s^2 = (4 - 4 / 2) / 1 = 2
  EXPECT_FLOAT_EQ(mean[0], 2.0f);
  EXPECT_DOUBLE_EQ(lv[0], (2.0 / 4 + 2.0 / 2) / 4);
  EXPECT_FLOAT_EQ(var[0], 0.5f + 8 * float((2.0 / 4 + 2.0 / 2) / 4));
  EXPECT_FLOAT_EQ(mean[1], 1.0f);
  EXPECT_DOUBLE_EQ(lv[1], 0.0);
  float m2[3] = {0, 0, 0}, v2[3] = {0, 0, 0};
  lucent::render_detail::add_light_halves(la, qa, 4, lb, qb, 0, 8, m2, v2, lv);
  EXPECT_FLOAT_EQ(m2[0], 1.0f);
  EXPECT_DOUBLE_EQ(lv[0], 2.0 / 4);
}

// Half A's plan and gain read nothing of half A's pilot (what keeps its mean unbiased,
// adaptive.hpp): changing A's variances and calibration sums leaves them as they were, while
// half B's plan and gain change (the control: B's do read A's pilot), and so do both gains when
// C changes (both read C).
TEST(AdaptivePlan, AHalfsPlanReadsNothingOfItsOwnPilot) {
  const int W = 4, H = 4;
  lucent::render_detail::Pilot a, b, c;
  for (int i = 0; i < W * H; ++i) {
    a.v.push_back(0.01 + 0.02 * i);
    b.v.push_back(0.3 - 0.015 * i);
  }
  add_pixel(a, {1, 2, 3, 5});
  add_pixel(a, {0.2, 0.4, 0.3, 0.1});
  add_pixel(b, {2, 3, 3, 4});
  add_pixel(b, {0.1, 0.5, 0.2, 0.2});
  add_pixel(c, {1, 1, 3, 4});
  add_pixel(c, {0.3, 0.3, 0.1, 0.4});
  c.pixels = {0, 5};  // the calibration pixels, with the halves' values there (choose_radius)
  a.value = {0.5, 0.6, 0.7, 0.2, 0.2, 0.2};
  b.value = {0.4, 0.4, 0.4, 0.1, 0.3, 0.2};
  // 14 more calibration pixels: a plan uses a gain measured on 16 or more
  // (kMinCalibrationPixels; fewer take gain 1, which would hide what the gains read)
  for (int i = 2; i < W * H; ++i) {
    const double x = 0.1 * i;
    add_pixel(a, {x, 2 * x, x + 1, 0.5});
    add_pixel(b, {x + 0.2, x, 3 * x, 1});
    add_pixel(c, {2 * x, x, x + 0.5, 0.3});
    c.pixels.push_back(static_cast<std::size_t>(i == 5 ? 1 : i));
    for (int k = 0; k < 3; ++k) {
      a.value.push_back(x + 0.1 * k);
      b.value.push_back(x + 0.2);
    }
  }
  ASSERT_EQ(lucent::render_detail::kMinCalibrationPixels, 16u);
  using lucent::render_detail::plan_halves;
  const auto before = plan_halves(a, b, c, W, H, 1e-3, 0, 4, 4096);
  lucent::render_detail::Pilot a2 = a;
  for (double& x : a2.v) x *= 3;
  a2.sum[0] += 4;
  a2.sumsq[0] += 40;
  a2.sum[3] -= 0.3;
  a2.value[1] = 5;
  const auto after = plan_halves(a2, b, c, W, H, 1e-3, 0, 4, 4096);
  EXPECT_EQ(after.plan[0].counts, before.plan[0].counts);
  EXPECT_EQ(after.calib[0].gain, before.calib[0].gain);
  EXPECT_EQ(after.radius[0], before.radius[0]);
  EXPECT_EQ(after.under[0], before.under[0]);
  EXPECT_NE(after.under[1], before.under[1]);
  EXPECT_NE(after.plan[1].counts, before.plan[1].counts);
  EXPECT_NE(after.calib[1].gain, before.calib[1].gain);
  lucent::render_detail::Pilot c2 = c;
  c2.sum[0] += 1;
  const auto other_c = plan_halves(a, b, c2, W, H, 1e-3, 0, 4, 4096);
  EXPECT_NE(other_c.calib[0].gain, before.calib[0].gain);
  EXPECT_NE(other_c.calib[1].gain, before.calib[1].gain);
}

// A gain measured on fewer than 16 calibration pixels (a film of fewer pixels) is noise: the plan
// takes gain 1 (on a 1x1 film the gains ranged over 0.016-4, and the renders reached 2.8-3.2 E on
// average with both samplers; with gain 1, 0.6 E with Sobol and 1.0 E independent, 40 seeds).
TEST(AdaptivePlan, AGainMeasuredOnFewPixelsIsNotUsed) {
  using lucent::render_detail::calibrate_model;
  using lucent::render_detail::plan_halves;
  const int W = 4, H = 4;
  lucent::render_detail::Pilot a, b, c;
  for (int i = 0; i < W * H; ++i) {
    a.v.push_back(0.05);
    b.v.push_back(0.05);
    // the pilots agree far better than their variances say (a stratified sampler): gain < 1
    const double x = 1 + 0.01 * i;
    add_pixel(a, {x - 0.5, x + 0.5});
    add_pixel(b, {x - 0.5, x + 0.5});
    add_pixel(c, {x - 0.49, x + 0.51});
    c.pixels.push_back(static_cast<std::size_t>(i));
    for (int k = 0; k < 3; ++k) {
      a.value.push_back(x);
      b.value.push_back(x);
    }
  }
  const double gain = calibrate_model(b.sum, b.sumsq, b.count, c.sum, c.sumsq, c.count).gain;
  ASSERT_LT(gain, 0.1);
  EXPECT_EQ(plan_halves(a, b, c, W, H, 1e-3, 0, 4, 4096).calib[0].gain, gain);  // 16 pixels
  // one calibration pixel of one sample in C: 15 pixels measured
  lucent::render_detail::Pilot c15 = c;
  for (int k = 0; k < 3; ++k) c15.sum[k] = c15.sumsq[k] = 1;
  c15.count[0] = 1;
  const auto plans = plan_halves(a, b, c15, W, H, 1e-3, 0, 4, 4096);
  EXPECT_EQ(plans.calib[0].pixels, 15u);
  EXPECT_EQ(plans.calib[0].gain, 1.0);
  EXPECT_EQ(plans.calib[1].gain, 1.0);
}

// The halves' a-posteriori relMSE: analytic on one pixel (A = 1, B = 3: (1 - 3)^2 / 4 / (2^2 +
// 0.01)), pixels where a half has no sample left out; and on simulated halves of known variances
// (A_p ~ N(1, 0.05^2), B_p ~ N(1, 0.1^2), 40000 pixels) its mean is the variance of the average,
// (0.05^2 + 0.1^2) / 4 / (1 + 0.01), within 3% (the estimate's sd is ~0.7% there, plus the
// weight's value being noisy: < 0.5%).
TEST(AdaptivePlan, HalvesRelmseIsTheVarianceOfTheAverage) {
  using lucent::render_detail::halves_relmse;
  EXPECT_DOUBLE_EQ(halves_relmse({2, 2, 2, 7, 7, 7}, {2, 0}, {9, 9, 9, 1, 1, 1}, {3, 1}),
                   4.0 / 4 / (4 + 0.01));
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0, 1);
  const size_t n = 40000;
  std::vector<double> sa(n * 3), sb(n * 3);
  std::vector<std::uint32_t> na(n, 1), nb(n, 1);
  for (size_t i = 0; i < n * 3; ++i) {
    sa[i] = 1 + 0.05 * normal(rng);
    sb[i] = 1 + 0.1 * normal(rng);
  }
  const double expected = (0.05 * 0.05 + 0.1 * 0.1) / 4 / 1.01;
  EXPECT_NEAR(halves_relmse(sa, na, sb, nb), expected, 0.03 * expected);
}

// The raise's neighbourhood from C (choose_radius), on a 32 x 32 film whose every pixel is a
// calibration pixel, C's relative variances set exactly (two samples 1 +- d per pixel, weighed
// by the pilot's value 1). Where C's variances are the pilot's (genuine variation: a 4 x 4 block
// at 20 in a field of 0.5), the plan's per-pixel variances hold and the radius stays 1. Where
// the pilot and C each caught rare bright samples in a tenth of the pixels, different ones, C's
// bright pixels are where the pilot's plan puts few samples, and the radius grows until the
// mean over the neighbourhood covers them (U <= 1.1).
TEST(AdaptivePlan, RaiseRadiusGrowsWhenThePilotMissedWhatCDrew) {
  using lucent::render_detail::choose_radius;
  using lucent::render_detail::Pilot;
  const int W = 32, H = 32, N = W * H;
  auto make = [&](const std::vector<double>& ov, const std::vector<double>& cv) {
    std::pair<Pilot, Pilot> oc;
    Pilot &o = oc.first, &c = oc.second;
    o.v = ov;
    for (int i = 0; i < N; ++i) {
      c.pixels.push_back(i);
      c.count.push_back(2);
      const double d = std::sqrt(cv[i] * 1.01 / 2);
      for (int ch = 0; ch < 3; ++ch) {
        o.value.push_back(1);
        c.sum.push_back(2);
        c.sumsq.push_back(2 * (1 + d * d));
      }
    }
    return oc;
  };
  std::vector<double> blob(N, 0.5);
  for (int y = 10; y < 14; ++y)
    for (int x = 20; x < 24; ++x) blob[y * W + x] = 20;
  auto [o1, c1] = make(blob, blob);
  double u = -1;
  EXPECT_EQ(choose_radius(o1, c1, W, H, &u), 1);
  EXPECT_LE(u, 1.0);
  std::vector<double> ov(N, 0.01), cv(N, 0.01);
  for (int i = 0; i < N; ++i) {
    if (i % 10 == 0) ov[i] = 10;
    if (i % 10 == 5) cv[i] = 10;
  }
  auto [o2, c2] = make(ov, cv);
  const int r = choose_radius(o2, c2, W, H, &u);
  RecordProperty("radius", r);
  RecordProperty("under", std::to_string(u));
  EXPECT_GT(r, 1);
  EXPECT_LE(u, 1.1);
  o2.value.clear();  // without the pilot's values (a budget's plan): the 3 x 3 raise
  EXPECT_EQ(choose_radius(o2, c2, W, H), 1);
}

// The warning of a render whose halves say it missed its target: none within 1.5 times the
// target (128 x 128: 1.52 with the estimate's noise), nor without a target or when cancelled;
// otherwise one line with the ratio. On a 2 x 2 film the estimate's noise widens it to 2.7.
TEST(AdaptivePlan, TargetShortfallIsReportedAbove1Point5TimesTheTarget) {
  RenderResult r;
  EXPECT_EQ(lucent::target_shortfall(r), "");
  r.mean.width = r.mean.height = 2;
  r.target_error = 1e-3;
  r.halves_relmse = 2.6e-3;
  EXPECT_EQ(lucent::target_shortfall(r), "");
  r.halves_relmse = 2.8e-3;
  EXPECT_NE(lucent::target_shortfall(r), "");
  r.mean.width = r.mean.height = 128;
  r.halves_relmse = 1.4e-3;
  EXPECT_EQ(lucent::target_shortfall(r), "");
  r.halves_relmse = 2.2e-3;
  EXPECT_EQ(lucent::target_shortfall(r),
            "the halves' difference estimates relMSE 0.0022, 2.2 times the target 0.001 (rare "
            "bright samples that no pilot foresees, or the --spp cap): lower --target-error or "
            "raise --spp (the path integrator's clamp trades such samples for bias)");
  // a target far below what a float holds: the ratio in three digits (it printed hundreds, and
  // the line lost its advice)
  r.target_error = 1e-300;
  r.halves_relmse = 1.57e-5;
  EXPECT_EQ(lucent::target_shortfall(r),
            "the halves' difference estimates relMSE 1.57e-05, 1.57e+295 times the target 1e-300 "
            "(rare bright samples that no pilot foresees, or the --spp cap): lower --target-error "
            "or raise --spp (the path integrator's clamp trades such samples for bias)");
  r.cancelled = true;
  EXPECT_EQ(lucent::target_shortfall(r), "");
}

// A render that a time limit stopped short of its plan: in the pilot the warning is always
// given (no plan was made and nothing was estimated: the halves' difference may be 0, where only
// one half has samples); after the pilot it names the time limit, not the plan's causes, when the
// halves are above the limit. A cancelled render gets none (its last line says how far it got).
TEST(AdaptivePlan, TargetShortfallNamesTheTimeLimit) {
  RenderResult r;
  r.mean.width = r.mean.height = 128;
  r.target_error = 1e-3;
  r.spp = 3;
  r.planned_spp = 66;
  r.pilot_incomplete = r.plan_incomplete = true;
  EXPECT_EQ(lucent::target_shortfall(r),
            "the time limit stopped the render in its pilot, at 3 of its 66 spp: no plan was "
            "made and the error is not estimated (target 0.001): raise --time");
  r.pilot_incomplete = false;
  r.spp = 100;
  r.planned_spp = 400;
  r.halves_relmse = 1.4e-3;  // within 1.5 E: no warning
  EXPECT_EQ(lucent::target_shortfall(r), "");
  r.halves_relmse = 2.2e-3;
  EXPECT_EQ(lucent::target_shortfall(r),
            "the halves' difference estimates relMSE 0.0022, 2.2 times the target 0.001: the time "
            "limit stopped the render at 100 of the 400 spp its plan asked for: raise --time");
  r.cancelled = true;
  EXPECT_EQ(lucent::target_shortfall(r), "");
  r.cancelled = false;
  r.pilot_incomplete = true;
  r.cancelled = true;
  EXPECT_EQ(lucent::target_shortfall(r), "");
}

// The weighing value: analytic on a 3 x 3 film of grey pixels (1, the same in the 3 channels
// but for the blue channel's + 20) with a firefly at the centre (10): the centre gets its 8
// neighbours' mean, 1; a corner keeps its own 1 (below its neighbours' (1 + 1 + 10) / 3). A pixel
// without samples is no neighbour: with the top-middle pixel absent (100) and the top-right one
// bright (7), the latter gets the mean of its other two neighbours, (10 + 1) / 2; `add` is added.
// A 1 x 1 film keeps its own mean.
TEST(AdaptivePlan, NeighbourValuesLeaveThePixelOut) {
  using lucent::render_detail::neighbour_values;
  std::vector<double> mean(27);
  for (int i = 0; i < 9; ++i)
    for (int c = 0; c < 3; ++c) mean[i * 3 + c] = (i == 4 ? 10 : 1) + (c == 2 ? 20 : 0);
  std::vector<std::uint32_t> present(9, 1);
  std::vector<double> v = neighbour_values(mean, present, 3, 3);
  EXPECT_DOUBLE_EQ(v[4 * 3], 1);
  EXPECT_DOUBLE_EQ(v[4 * 3 + 2], 21);
  EXPECT_DOUBLE_EQ(v[0], 1);
  present[1] = 0;
  for (int c = 0; c < 3; ++c) {
    mean[1 * 3 + c] = 100;
    mean[2 * 3 + c] = 7;
  }
  const std::vector<double> add(27, 0.5);
  v = neighbour_values(mean, present, 3, 3, &add);
  EXPECT_DOUBLE_EQ(v[2 * 3], (10 + 1) / 2.0 + 0.5);
  EXPECT_DOUBLE_EQ(v[4 * 3], (1 + 7 + 1 + 1 + 1 + 1 + 1) / 7.0 + 0.5);
  v = neighbour_values({2, 3, 4}, {7}, 1, 1);
  EXPECT_EQ(v, (std::vector<double>{2, 3, 4}));
}

// Why the error model weighs a pixel by its neighbours' value: on pixels whose samples are
// heavy-tailed (0.4 with probability 0.99, 10.4 with 0.01: mean 0.5, variance 0.99, relative
// variance 0.99 / 0.26 = 3.81 for every pixel), 32 samples each, the mean over 4096 pixels of
// s^2 / (own mean^2 + 0.01) falls far below the truth (a pixel that drew the bright sample has
// both a large s^2 and a large mean; measured 0.43 of it), while weighed by the neighbours'
// mean it stays within 10% of it (its sd over pixels of this mean is ~3%).
TEST(AdaptivePlan, NeighbourValuesKeepTheRelativeVarianceOfRarePaths) {
  using lucent::render_detail::neighbour_values;
  using lucent::render_detail::relative_variance;
  using lucent::render_detail::sample_means;
  const int w = 64, h = 64, n = 32;
  const std::size_t npix = std::size_t(w) * h;
  std::vector<double> sum(npix * 3, 0.0), sumsq(npix * 3, 0.0);
  std::vector<std::uint32_t> count(npix, n);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (std::size_t i = 0; i < npix; ++i)
    for (int k = 0; k < n; ++k) {
      const double x = u(rng) < 0.01 ? 10.4 : 0.4;  // one value for the 3 channels
      for (int c = 0; c < 3; ++c) {
        sum[i * 3 + c] += x;
        sumsq[i * 3 + c] += x * x;
      }
    }
  const double truth = 0.99 / (0.25 + 0.01);
  auto mean_of = [](const std::vector<double>& v) {
    double t = 0;
    for (double x : v) t += x;
    return t / double(v.size());
  };
  const double own = mean_of(relative_variance(sum, sumsq, count));
  const std::vector<double> value = neighbour_values(sample_means(sum, count), count, w, h);
  const double neighbours = mean_of(relative_variance(sum, sumsq, count, &value));
  RecordProperty("own_over_truth", std::to_string(own / truth));
  RecordProperty("neighbours_over_truth", std::to_string(neighbours / truth));
  EXPECT_LT(own, 0.6 * truth);
  EXPECT_NEAR(neighbours, truth, 0.1 * truth);
}

/// The plastic-and-lamp scene of the adaptive tests: a noisy glossy highlight and soft shadows
/// beside flat, quickly converged floor.
Scene adaptive_scene() {
  Scene s = lamp_scene(SamplerType::Independent);
  s.film.width = 24;
  s.film.height = 24;
  return s;
}

/// An adaptive render of `s` to the relMSE target E, with the default pilot.
RenderResult render_to_target(const Scene& s, double E) {
  lucent::Renderer r(lucent::test::session_options());
  r.set_scene(s);
  lucent::AdaptiveOptions ao;
  ao.target_error = E;
  r.render_adaptive(ao);
  return r.result();
}

/// The reference of the adaptive tests: a uniform render of `s` with another seed.
RenderResult reference_render(Scene s, std::uint64_t spp) {
  s.integrator.seed = 0x51ed5eedu;
  lucent::RenderOptions ro;
  ro.spp = static_cast<int>(spp);
  return lucent::test::render(s, ro);
}

// --target-error E: the relMSE of the result against a reference (the reference's own expected
// share subtracted) is within a factor 2 of E, and so is the render's own estimate (the plan
// comes from the default pilot, 32 samples per half, whose variances are noisy: measured 0.95 E,
// 1.05 E before choose_radius; with 8 per half, 1.9 E). The
// reference has 20 times the adaptive render's mean spp, so its own share is about 1/20 of E.
TEST(Adaptive, TargetErrorIsMet) {
  const double E = 5e-4;
  Scene s = adaptive_scene();
  RenderResult a = render_to_target(s, E);
  ASSERT_GT(a.spp, 0u);
  EXPECT_EQ(a.target_error, E);
  RecordProperty("estimated_over_target", std::to_string(a.estimated_relmse / E));
  EXPECT_LE(a.estimated_relmse, 2 * E);

  RenderResult ref = reference_render(s, 20 * a.spp);
  lucent::CompareResult c = lucent::compare_images(a, ref);
  double ref_noise = 0;
  const size_t npix = ref.samples.size();
  for (size_t i = 0; i < npix; ++i)
    for (int k = 0; k < 3; ++k) {
      const double m = ref.mean.rgb[i * 3 + k];
      ref_noise += ref.variance.rgb[i * 3 + k] / ref.samples[i] / (m * m + 0.01);
    }
  ref_noise /= 3.0 * double(npix);
  const double achieved = c.relmse - ref_noise;
  RecordProperty("achieved_over_target", std::to_string(achieved / E));
  EXPECT_LT(achieved, 2 * E) << "relMSE " << c.relmse << " - reference noise " << ref_noise
                             << ", mean spp " << a.spp;
  EXPECT_GT(achieved, E / 2) << "relMSE " << c.relmse << " - reference noise " << ref_noise
                             << ": stopped far beyond the target (wasted samples)";
  // and it adapted: the counts range over more than a factor 2
  const auto [lo, hi] = std::minmax_element(a.samples.begin(), a.samples.end());
  EXPECT_GT(*hi, 3 * *lo);
}

/// The lamp scene of the adaptive tests with the Sobol sampler, on a 48 x 48 film: 2304
/// calibration pixels (all of them), where 576 leave the gain noisy (measured over 3 seeds with
/// the independent sampler: 0.78 to 2.7 on 24 x 24, 0.73 to 1.4 on 48 x 48).
Scene sobol_adaptive_scene() {
  Scene s = adaptive_scene();
  s.integrator.sampler = SamplerType::Sobol;
  s.film.width = s.film.height = 48;
  return s;
}

// --target-error E with the Sobol sampler: the calibrated plan (adaptive.hpp) reaches E without
// the uncalibrated plan's waste. The relMSE against a Sobol reference of 16 times the spp (its
// own share included: the reference's per-pixel variances / n over-state a Sobol render's noise,
// so they are not subtracted) is between E / 4 and 2 E. Measured: 0.31 E (0.51 E before
// choose_radius, which widens the raise on some seeds); over seeds 1-6 of `lucent render
// --target-error 1e-4` against 32768 spp, 0.23-0.54 E (0.23-0.46 E before it: the lower bound
// is tight for this scene's seeds, either way). Below E, not at it: the gain is measured at the
// pilot's 32 samples per half and
// Sobol's error falls faster than 1 / n beyond (conservative by design); an uncalibrated plan stops
// far lower (scenes/default.json: 0.13 E). The halves' a-posteriori estimate is within a factor 2
// of that relMSE (measured 0.5 to 1 of it: the share of the reference and the noise of a 2304-pixel
// estimate).
TEST(Adaptive, SobolTargetErrorIsMet) {
  const double E = 1e-4;
  Scene s = sobol_adaptive_scene();
  RenderResult a = render_to_target(s, E);
  RecordProperty("gain_a", std::to_string(a.model_gain_a));
  RecordProperty("gain_b", std::to_string(a.model_gain_b));
  EXPECT_LE(a.planned_relmse, E * (1 + 1e-9));

  RenderResult ref = reference_render(s, 16 * a.spp);
  const double relmse = lucent::compare_images(a, ref).relmse;
  RecordProperty("achieved_over_target", std::to_string(relmse / E));
  RecordProperty("halves_over_achieved", std::to_string(a.halves_relmse / relmse));
  EXPECT_LT(relmse, 2 * E) << "mean spp " << a.spp;
  EXPECT_GT(relmse, E / 4) << "mean spp " << a.spp << ": stopped far beyond the target";
  EXPECT_LT(a.halves_relmse, 2 * relmse);
  EXPECT_GT(a.halves_relmse, relmse / 4);
}

// The calibration takes the samples the sampler needs: with Sobol samples both gains are well
// below 1 and the samples planned beyond the pilot far fewer than with independent samples,
// whose gains are near 1 (~1: the v / n model is right for them). The independent sampler's
// plan is the uncalibrated plan of a Sobol render: the pilot's per-sample variances have the
// same expectation with either sampler (each sample is uniform), so with gain 1 the counts are
// the same. Measured: Sobol gain (mean of the two) 0.42, independent 0.92, Sobol's samples
// beyond the pilot 0.37 of the independent sampler's; over 4 other seeds 0.32 to 0.71, 0.87 to
// 1.19 and 0.20 to 0.56.
TEST(Adaptive, SobolCalibrationTakesFewerSamples) {
  const double E = 1e-4;
  double added[2], gain[2];
  for (SamplerType t : {SamplerType::Sobol, SamplerType::Independent}) {
    Scene s = sobol_adaptive_scene();
    s.integrator.sampler = t;
    RenderResult a = render_to_target(s, E);
    const int k = t == SamplerType::Sobol ? 0 : 1;
    gain[k] = (a.model_gain_a + a.model_gain_b) / 2;
    double n = 0;  // samples of the halves (the calibration's stream is not in the image)
    for (std::uint32_t c : a.samples) n += c;
    added[k] = n / double(a.samples.size()) - lucent::AdaptiveOptions{}.min_spp;
  }
  RecordProperty("sobol_gain", std::to_string(gain[0]));
  RecordProperty("independent_gain", std::to_string(gain[1]));
  RecordProperty("added_ratio", std::to_string(added[0] / added[1]));
  EXPECT_LT(gain[0], 0.8);
  EXPECT_GT(gain[1], 0.7);
  EXPECT_LT(gain[1], 1.4);
  EXPECT_GT(added[1], 50) << "the independent plan hardly went beyond the pilot";
  EXPECT_LT(added[0], 0.7 * added[1]);
}

// Unbiased: an adaptive render (independent halves) against a uniform render of about the same
// spp and another seed, by lucent compare's z-test (per pixel-channel at family-wise alpha 0.01,
// and the image means). The control: the same test catches a 2% change in the lamp.
TEST(Adaptive, MeanIsUnbiased) {
  Scene s = adaptive_scene();
  lucent::Renderer r(lucent::test::session_options());
  r.set_scene(s);
  lucent::AdaptiveOptions ao;
  ao.budget_spp = 256;
  r.render_adaptive(ao);
  RenderResult a = r.result();
  EXPECT_NEAR(double(a.spp), 256, 16);

  Scene u = s;
  u.integrator.seed = 0xabcdefu;
  lucent::RenderOptions o;
  o.spp = 256;
  RenderResult uniform = lucent::test::render(u, o);
  lucent::CompareResult c = lucent::compare_images(a, uniform);
  EXPECT_TRUE(c.passed) << c.summary();

  for (auto& m : u.materials)
    if (m.emissive()) m.emission *= 1.02;
  RenderResult brighter = lucent::test::render(u, o);
  EXPECT_FALSE(lucent::compare_images(a, brighter).passed) << "the test has no power";
}

// A time limit that ends an adaptive render in its pilot: the result still says it is a target
// render (target_error was set only once the pilot was done, so `lucent render --target-error E
// --time T` stopped in the pilot printed no adaptive line and no warning, exit 0, as if complete),
// that it stopped in the pilot and how far it got, and target_shortfall says so. A second call
// without a limit completes the pilot and the plan.
TEST(Adaptive, TimeLimitInThePilotIsReported) {
  Scene s = adaptive_scene();
  lucent::Renderer r(lucent::test::session_options());
  r.set_scene(s);
  lucent::AdaptiveOptions ao;
  ao.target_error = 1e-3;
  ao.min_spp = 8;
  ao.max_seconds = 1e-9;  // one job, the first: part of the pilot
  r.render_adaptive(ao);
  RenderResult a = r.result();
  EXPECT_FALSE(a.cancelled);
  EXPECT_EQ(a.target_error, 1e-3);
  EXPECT_TRUE(a.pilot_incomplete);
  EXPECT_TRUE(a.plan_incomplete);
  EXPECT_GE(a.planned_spp, 8u);  // both halves' pilot, and the calibration's
  EXPECT_LT(a.spp, a.planned_spp);
  EXPECT_EQ(lucent::target_shortfall(a).rfind("the time limit stopped the render in its pilot", 0),
            0u)
      << lucent::target_shortfall(a);

  ao.max_seconds = 0;
  r.render_adaptive(ao);
  RenderResult b = r.result();
  EXPECT_FALSE(b.pilot_incomplete);
  EXPECT_FALSE(b.plan_incomplete);
  EXPECT_EQ(b.spp, b.planned_spp);
  EXPECT_GT(b.estimated_relmse, 0.0);
}

// The one-shot lucent::render with RenderOptions::target_error renders adaptively, as a
// session's render_adaptive does with the same target, pilot (min_spp) and cap (spp): the same
// samples per pixel (the plan depends only on the pilot's samples), the same image to the float
// rounding of the passes, every pixel at least its pilot, and a target low enough that the cap
// binds on the noisiest pixels. Forwarding neither min_spp (default 64) nor spp (default 16384)
// would change the counts.
TEST(Adaptive, OneShotRenderForwardsTargetPilotAndCap) {
  const double E = 1e-4;
  Scene s = adaptive_scene();
  lucent::RenderOptions o;
  o.target_error = E;
  o.min_spp = 16;
  o.spp = 512;
  RenderResult one = lucent::test::render(s, o);

  lucent::Renderer r(lucent::test::session_options());
  r.set_scene(s);
  lucent::AdaptiveOptions ao;
  ao.target_error = E;
  ao.min_spp = 16;
  ao.max_spp = 512;
  r.render_adaptive(ao);
  RenderResult session = r.result();

  EXPECT_EQ(one.target_error, E);
  EXPECT_GT(one.halves_relmse, 0.0);
  ASSERT_EQ(one.samples.size(), session.samples.size());
  EXPECT_TRUE(one.samples == session.samples);
  const auto [lo, hi] = std::minmax_element(one.samples.begin(), one.samples.end());
  EXPECT_GE(*lo, 16u);
  EXPECT_EQ(*hi, 512u) << "the cap binds";
  EXPECT_LT(lucent::compare_images(one, session).max_abs_error, 1e-5);
}

// ---- clamping --------------------------------------------------------------------------------

// integrator.clamp: the kernel and the reference compute the same clamped estimator (z-test), its
// mean is lower than the unclamped one by far more than the noise (the bias that converge
// shows), and its variance lower.
// The quad lamp: a clamped estimator's mean depends on how each contribution was sampled, and
// the kernel and the reference sample a quad lamp the same way (not a sphere lamp).
TEST(Clamp, KernelMatchesReferenceAndTheBiasIsVisible) {
  Scene s = scene_with(quad_lamp_json(), SamplerType::Independent);
  s.integrator.clamp = 0.1;
  lucent::RenderOptions o;
  o.spp = 128;
  RenderResult k = lucent::test::render(s, o);
  Scene rs = s;
  rs.integrator.seed ^= 0x9e3779b9u;
  lucent::ReferenceOptions ro;
  ro.spp = 128;
  RenderResult ref = lucent::render_reference(rs, ro);
  lucent::CompareResult c = lucent::compare_images(k, ref);
  EXPECT_TRUE(c.passed) << "A = kernel, B = reference, both clamped\n" << c.summary();

  Scene free = s;
  free.integrator.clamp = 0;
  RenderResult unclamped = lucent::test::render(free, o);
  lucent::CompareResult b = lucent::compare_images(k, unclamped);
  for (int ch = 0; ch < 3; ++ch) EXPECT_LT(b.mean_z[ch], -5) << "channel " << ch;
  double vk = 0, vu = 0;
  for (size_t i = 0; i < k.variance.rgb.size(); ++i)
    vk += k.variance.rgb[i], vu += unclamped.variance.rgb[i];
  EXPECT_LT(vk, 0.8 * vu);
}

}  // namespace

}  // namespace test_sampling
