// The device's light sampling against the pdfs the integrator uses for MIS: a chi-square test
// of the sampled directions (sphere lights by cone, triangles by area, environment maps by
// texel, and a power-proportional mixture), through kernels/test/light_probe.cl.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "cl/kernel_source.hpp"
#include "cl/program_cache.hpp"
#include "probe_launch.hpp"
#include "render/device_scene.hpp"
#include "render/pack.hpp"
#include "support.hpp"

namespace test_kernel_light_sampling {

namespace {

struct Probe {
  lucent::cl_util::Context ctx{lucent::test::device()};
  cl::Program program = lucent::cl_util::build_program_cached(
      ctx,
      lucent::detail::assemble_kernel_source("test/light_probe.cl", lucent::test::kernel_dir()),
      "-cl-std=CL1.2", lucent::test::cache_dir());
};

Probe& probe() {
  static Probe p;
  return p;
}

// Runs the probe kernel `name` (scene arguments, point p, an input and an output buffer), one
// work-item per element of `in`, and returns its outputs.
template <class Out>
std::vector<Out> run_probe(const lucent::render_detail::DeviceScene& dev, const char* name,
                           const cl_float4& p, const std::vector<cl_float4>& in) {
  Probe& pr = probe();
  cl::Buffer bi(pr.ctx.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                in.size() * sizeof(cl_float4), const_cast<cl_float4*>(in.data()));
  cl::Buffer bo(pr.ctx.context, CL_MEM_WRITE_ONLY, in.size() * sizeof(Out));
  cl::Kernel k(pr.program, name);
  lucent::test::set_args(k, dev.set_args(k), p, bi, bo);
  lucent::test::launch_probe(pr.ctx.queue, k, in.size());
  return lucent::test::read_back<Out>(pr.ctx.queue, bo, in.size());
}

// Samples N directions from point (0,0,0) with the scene's lights, bins them over
// (cos theta, phi) of the whole sphere (the lights sit near the equator, z ~ 0, where the bins
// are regular), and compares with N times the integral of the probe's pdf over each bin (see
// the quadrature below). Bins with expected count < 5 are pooled. Fails when
// the p-value is below 1e-4. Also: the pdf integral equals the fraction of successful samples
// (within 1%), and each sample's reported pdf equals the pdf function at its direction.
void chi_square_lights(const std::string& json, const char* name, bool single_light = true) {
  lucent::Scene scene = lucent::parse_scene(json, lucent::test::temp_dir() + "/lights.json");
  lucent::render_detail::PackedScene packed = lucent::render_detail::pack_scene(scene);
  Probe& pr = probe();
  lucent::render_detail::DeviceScene dev(pr.ctx, packed);
  const int N = 1 << 18, NT = 48, NP = 96, SUB = 4;
  const cl_float4 p = {{0, 0, 0, 0}};

  cl::Buffer out(pr.ctx.context, CL_MEM_WRITE_ONLY, N * sizeof(cl_float4));
  cl::Kernel ks(pr.program, "probe_light_sample");
  lucent::test::set_args(ks, dev.set_args(ks), p, out);
  lucent::test::launch_probe(pr.ctx.queue, ks, N);
  std::vector<cl_float4> s = lucent::test::read_back<cl_float4>(pr.ctx.queue, out, N);

  std::vector<double> observed(NT * NP, 0.0);
  int produced = 0;
  for (const auto& v : s) {
    if (v.s[3] < 0) continue;
    ++produced;
    double z = std::clamp<double>(v.s[2], -1, 1);
    int ti = std::min(NT - 1, int((z + 1) / 2 * NT));
    double phi = std::atan2(v.s[1], v.s[0]);
    if (phi < 0) phi += 2 * M_PI;
    int pi = std::min(NP - 1, int(phi / (2 * M_PI) * NP));
    observed[ti * NP + pi] += 1;
  }

  // the probe's pdf at a list of directions
  auto eval_pdf = [&](const std::vector<cl_float4>& dirs) {
    return run_probe<float>(dev, "probe_light_pdf", p, dirs);
  };
  // sub x sub midpoint directions of cell (ti, pi) in (z, phi)
  auto cell_dirs = [&](int ti, int pi, int sub, std::vector<cl_float4>& dirs) {
    for (int i = 0; i < sub; ++i)
      for (int j = 0; j < sub; ++j) {
        double z = -1 + 2 * (ti + (i + 0.5) / sub) / NT,
               phi = 2 * M_PI * (pi + (j + 0.5) / sub) / NP;
        double r = std::sqrt(std::max(0.0, 1 - z * z));
        dirs.push_back({{float(r * std::cos(phi)), float(r * std::sin(phi)), float(z), 0}});
      }
  };

  // the reported pdf of some samples against the pdf function at their directions. A sample
  // reports the pdf of the light that produced it; with one light that is the whole density,
  // with several it is one term of the sum.
  std::vector<cl_float4> sample_dirs;
  std::vector<int> picked;
  for (int i = 0; i < N && picked.size() < 4000; i += 97)
    if (s[i].s[3] > 0) {
      picked.push_back(i);
      sample_dirs.push_back(s[i]);
    }
  std::vector<float> sample_pdf = eval_pdf(sample_dirs);
  for (size_t k = 0; k < picked.size(); ++k) {
    double reported = s[picked[k]].s[3], evaluated = sample_pdf[k];
    if (single_light)
      ASSERT_NEAR(reported, evaluated, 2e-3 * reported) << name << ": sample " << picked[k];
    else
      ASSERT_LE(reported, evaluated * (1 + 2e-3)) << name << ": sample " << picked[k];
  }

  // Expected counts: N times the pdf integrated over each cell by a 4x4 midpoint rule, refined
  // to 48x48 where the 16 values differ by more than 1% (light edges, texel edges) and in the
  // neighbours of such cells, so that the quadrature error stays well below the counting noise.
  const double cell_area = (2.0 / NT) * (2 * M_PI / NP);  // dz dphi = solid angle
  std::vector<cl_float4> dirs;
  for (int ti = 0; ti < NT; ++ti)
    for (int pi = 0; pi < NP; ++pi) cell_dirs(ti, pi, SUB, dirs);
  std::vector<float> pdf = eval_pdf(dirs);
  std::vector<double> expected(NT * NP, 0.0);
  std::vector<int> refine;
  for (int c = 0; c < NT * NP; ++c) {
    float lo = pdf[c * SUB * SUB], hi = lo;
    double sum = 0;
    for (int k = 0; k < SUB * SUB; ++k) {
      lo = std::min(lo, pdf[c * SUB * SUB + k]);
      hi = std::max(hi, pdf[c * SUB * SUB + k]);
      sum += pdf[c * SUB * SUB + k];
    }
    expected[c] = sum / (SUB * SUB) * cell_area * N;
    if (hi > lo * 1.01f) refine.push_back(c);
  }
  // an edge that clips a cell's corner may miss all 16 points: refine the neighbours too
  std::vector<char> mark(NT * NP, 0);
  for (int c : refine)
    for (int dt = -1; dt <= 1; ++dt)
      for (int dp = -1; dp <= 1; ++dp) {
        int t = c / NP + dt, ph = (c % NP + dp + NP) % NP;
        if (t >= 0 && t < NT) mark[t * NP + ph] = 1;
      }
  refine.clear();
  for (int c = 0; c < NT * NP; ++c)
    if (mark[c]) refine.push_back(c);
  const int FINE = 48;
  for (size_t start = 0; start < refine.size(); start += 256) {
    std::vector<cl_float4> fine;
    size_t end = std::min(refine.size(), start + 256);
    for (size_t k = start; k < end; ++k) cell_dirs(refine[k] / NP, refine[k] % NP, FINE, fine);
    std::vector<float> fp = eval_pdf(fine);
    for (size_t k = start; k < end; ++k) {
      double sum = 0;
      for (int m = 0; m < FINE * FINE; ++m) sum += fp[(k - start) * FINE * FINE + m];
      expected[refine[k]] = sum / (FINE * FINE) * cell_area * N;
    }
  }
  double integral = 0;
  for (double e : expected) integral += e / N;
  EXPECT_NEAR(integral, double(produced) / N, 0.01) << name << ": pdf integral vs sampling success";

  lucent::test::PooledChi2 c = lucent::test::pooled_chi2(observed, expected);
  ASSERT_GE(c.cells, 20) << name << ": too few populated bins for a meaningful test";
  double pval = lucent::test::chi2_pvalue(c.chi2, c.cells - 1);
  EXPECT_GT(pval, 1e-4) << name << ": chi2 " << c.chi2 << " over " << c.cells << " cells";
}

const char* kMats =
    R"("materials": {"lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [2, 3, 4]},
                                      "dim": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [0.5, 0.5, 0.5]}})";

TEST(KernelLightSampling, SphereLightCone) {
  chi_square_lights(std::string("{") + kMats + R"(, "shapes": [
      {"type": "sphere", "center": [2, 0.3, 0.2], "radius": 0.5, "material": "lamp"}]})",
                    "sphere, small cone");
}

TEST(KernelLightSampling, SphereLightWideCone) {
  chi_square_lights(std::string("{") + kMats + R"(, "shapes": [
      {"type": "sphere", "center": [0.1, 0.7, -0.2], "radius": 0.6, "material": "lamp"}]})",
                    "sphere, wide cone");
}

TEST(KernelLightSampling, TriangleLightsByArea) {
  chi_square_lights(std::string("{") + kMats + R"(, "shapes": [
      {"type": "triangles", "material": "lamp", "positions": [[1, -1, -0.5], [1.5, 1, -0.8], [0.8, 0.2, 1], [1.1, -1.2, 1]],
       "indices": [0, 2, 1, 0, 3, 2]}]})",
                    "triangles");
}

TEST(KernelLightSampling, EnvironmentMap) {
  std::string dir = lucent::test::temp_dir();
  lucent::Image env{24, 12, std::vector<float>(24 * 12 * 3)};
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 24; ++x)
      for (int c = 0; c < 3; ++c)
        env.pixel(x, y)[c] =
            float(0.05 + ((x * 7 + y * 3) % 11) * 0.3 + (x == 5 && y == 3 ? 40 : 0));
  lucent::write_image(dir + "/env.pfm", env);
  chi_square_lights(R"({"lights": [{"type": "environment", "file": ")" + dir + R"(/env.pfm"}]})",
                    "environment map");
}

// An environment map whose texels' shares lie far apart: texel (10, 16) holds nearly all the
// weight, every other texel about 2.8 lattice steps (2^-24) of it.
std::string write_lopsided_env_map(int w, int h) {
  lucent::Image env{w, h, std::vector<float>(size_t(w) * h * 3, 1.0f)};
  for (int c = 0; c < 3; ++c) env.pixel(10, h / 2)[c] = 6e6f;
  std::string path = lucent::test::temp_dir() + "/lopsided.pfm";
  lucent::write_image(path, env);
  return path;
}

// The texel CDF of an environment map lies on the lattice of the kernel's random numbers, as the
// light-selection CDF does (below): a texel's probability is exactly its interval, the pdf the
// kernel divides by. Rounded to floats on their own, the entries below 1/2 fell between lattice
// points, and a texel of 2.8 steps was drawn with 2 or 3 steps' probability (+-36%).
TEST(KernelLightSampling, EnvironmentMapCdfLiesOnTheLattice) {
  const int w = 64, h = 32;
  lucent::Scene s = lucent::test::scene_from(R"({"lights": [{"type": "environment", "file": ")" +
                                             write_lopsided_env_map(w, h) + R"("}]})");
  const lucent::render_detail::PackedScene p = lucent::render_detail::pack_scene(s);
  ASSERT_EQ(p.lights.size(), 1u);
  const size_t first = p.lights[0].p.env_map.cdf;
  ASSERT_EQ(p.light_cdf.size(), first + w * h + 1);
  EXPECT_EQ(p.light_cdf[first], 0.0f);
  EXPECT_EQ(p.light_cdf.back(), 1.0f);
  int small = 0;
  for (size_t i = first; i < p.light_cdf.size(); ++i) {
    const double k = double(p.light_cdf[i]) * 16777216.0;
    ASSERT_EQ(k, std::floor(k)) << "texel cdf[" << i - first << "] is not on the 2^-24 lattice";
    if (i > first) {
      ASSERT_GE(p.light_cdf[i], p.light_cdf[i - 1]) << i - first;
      small += p.light_cdf[i] - p.light_cdf[i - 1] < 4.0f / 16777216.0f;
    }
  }
  EXPECT_GT(small, w * h / 2) << "the map no longer has texels of a few lattice steps";
}

// The point inside the chosen texel is uniform over the texel, however few lattice points choose
// it: (u3, u2) place it across and down the texel. It used to be u1 rescaled to the texel's
// interval, which for a texel of 2 or 3 lattice points gave 2 or 3 columns of directions.
// Stratified (u3, u2) must come back as the point's position in the texel (to 1e-3), the
// direction must fall in the texel, and its pdf must be the texel's interval over its solid
// angle, as the pdf function gives.
TEST(KernelLightSampling, EnvironmentMapPointsFillTheTexel) {
  const int w = 64, h = 32, tx = 40, ty = h / 2, G = 16;
  lucent::Scene scene =
      lucent::test::scene_from(R"({"lights": [{"type": "environment", "file": ")" +
                               write_lopsided_env_map(w, h) + R"("}]})");
  const lucent::render_detail::PackedScene packed = lucent::render_detail::pack_scene(scene);
  const size_t k = packed.lights[0].p.env_map.cdf + size_t(ty) * w + tx;
  const double lo = double(packed.light_cdf[k]) * 16777216.0,
               hi = double(packed.light_cdf[k + 1]) * 16777216.0;
  ASSERT_GE(hi - lo, 1.0) << "the texel has no lattice point";
  ASSERT_LE(hi - lo, 4.0) << "the texel should have a few lattice points only";

  std::vector<cl_float4> u;
  for (double m = lo; m < hi; ++m)
    for (int i = 0; i < G; ++i)
      for (int j = 0; j < G; ++j)
        u.push_back({{0.5f, float(m / 16777216.0), (i + 0.5f) / G, (j + 0.5f) / G}});
  lucent::render_detail::DeviceScene dev(probe().ctx, packed);
  const std::vector<cl_float4> s =
      run_probe<cl_float4>(dev, "probe_light_sample_with", cl_float4{{0, 0, 0, 0}}, u);

  const double n = double(w) * h, texel_p = (hi - lo) / 16777216.0;
  for (size_t i = 0; i < s.size(); ++i) {
    ASSERT_GT(s[i].s[3], 0.0f) << "sample " << i << " was not produced";
    const double dx = s[i].s[0], dy = s[i].s[1], dz = s[i].s[2];
    // docs/rendering-model.md: u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi
    const double uu = 0.5 + std::atan2(dx, -dz) / (2 * M_PI), vv = std::acos(dy) / M_PI;
    const double fu = uu * w - tx, fv = vv * h - ty;
    ASSERT_NEAR(fu, u[i].s[3], 1e-3) << "sample " << i << ": across the texel";
    ASSERT_NEAR(fv, u[i].s[2], 1e-3) << "sample " << i << ": down the texel";
    const double sin_t = std::sqrt(dx * dx + dz * dz);
    EXPECT_NEAR(s[i].s[3], texel_p * n / (2 * M_PI * M_PI * sin_t), 1e-4 * s[i].s[3]) << i;
  }
}

TEST(KernelLightSampling, PowerProportionalMixture) {
  chi_square_lights(std::string("{") + kMats + R"(, "shapes": [
      {"type": "sphere", "center": [2, 0.3, 0.2], "radius": 0.5, "material": "lamp"},
      {"type": "sphere", "center": [-1, 1.5, -0.2], "radius": 0.3, "material": "dim"},
      {"type": "triangles", "material": "lamp", "positions": [[-1, -2, -1], [1, -2, -1], [0, -2, 1]], "indices": [0, 1, 2]}],
    "lights": [{"type": "environment", "radiance": [0.2, 0.2, 0.2]}, {"type": "point", "position": [0, 0, 3], "intensity": [1, 1, 1]}]})",
                    "mixture", false);
}

// The light-selection CDF lies on the 2^-24 lattice of the kernel's random numbers (lc_u01), and
// each light's pdf_select is exactly its interval: lc_cdf_search picks light i for the lattice
// points in [cdf[i-1], cdf[i]), so the probability the kernel divides by is the one it draws
// with. Rounded separately, the two differed by up to 2^-24 (6% of a light's share among 10^6).
TEST(KernelLightSampling, SelectionProbabilitiesAreTheCdfsIntervals) {
  std::string lights;
  for (int i = 0; i < 300; ++i)
    lights += std::string(i ? ", " : "") + R"({"type": "point", "position": [0, 0, 3], )" +
              R"("intensity": [)" + std::to_string(1 + (i * 37) % 101) + ", 1, 1]}";
  lucent::Scene s = lucent::test::scene_from(R"({"lights": [)" + lights + "]}");
  const lucent::render_detail::PackedScene p = lucent::render_detail::pack_scene(s);
  ASSERT_EQ(p.light_cdf.size(), 300u);
  EXPECT_EQ(p.light_cdf.back(), 1.0f);
  double total = 0;
  for (size_t i = 0; i < p.light_cdf.size(); ++i) {
    const double k = double(p.light_cdf[i]) * 16777216.0;
    EXPECT_EQ(k, std::floor(k)) << "cdf[" << i << "] is not on the 2^-24 lattice";
    const float below = i ? p.light_cdf[i - 1] : 0.0f;
    EXPECT_EQ(p.lights[i].pdf_select, p.light_cdf[i] - below) << i;
    EXPECT_GT(p.lights[i].pdf_select, 0.0f) << i;
    total += p.lights[i].pdf_select;
  }
  EXPECT_EQ(total, 1.0);
}

// Among more than 2^24 / 10 lights, one holding the power, the running sums' rounding gave many
// lights no lattice step: never chosen, a point light was never lit (2e6 dim point lights beside a
// bright one rendered 16% dark, image-mean z -11, without a word; the lights campaign). Each
// light now has a step at least, and a CDF in which every light has one is left as it was.
TEST(KernelLightSampling, EveryLightIsChosenAmongMillions) {
  const size_t n = 2000000;
  std::vector<double> w(n, 0.1 / double(n));
  w[n / 2] += 0.9;
  lucent::sys::HostVector<float> cdf;
  lucent::render_detail::append_selection_cdf(w, cdf);
  ASSERT_EQ(cdf.size(), n);
  EXPECT_EQ(cdf.back(), 1.0f);
  size_t never = 0;
  for (size_t i = 0; i < n; ++i) never += cdf[i] == (i ? cdf[i - 1] : 0.0f);
  EXPECT_EQ(never, 0u);
  // the dim lights hold one step each (0.1 / n is 0.84 of one), taken from the bright light
  EXPECT_EQ(double(cdf[n / 2]) - double(cdf[n / 2 - 1]), 1.0 - double(n - 1) / 16777216.0);
  lucent::sys::HostVector<float> few;
  lucent::render_detail::append_selection_cdf({0.5, 0.125, 0.375}, few);
  EXPECT_EQ(std::vector<float>(few.begin(), few.end()), (std::vector<float>{0.5f, 0.625f, 1.0f}));
}

// lc_cdf_search, the binary search of light selection and environment-map texels, takes its
// halves by a select in a number of steps that depends on n alone. Its index must be the
// definition's: the number of entries <= u, at most n - 1. CDFs of 1 to 70 entries with runs of
// equal entries (lights of zero share) and a last entry of 1 or just below; u at, just below and
// just above every entry, 0 and random.
TEST(KernelLightSampling, CdfSearchPicksTheIntervalOfU) {
  Probe& pr = probe();
  std::mt19937 gen(23);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  std::size_t checked = 0, wrong = 0;
  for (cl_uint n = 1; n <= 70; ++n) {
    std::vector<float> cdf(n);
    for (float& c : cdf) c = U(gen);
    for (cl_uint i = 1; i + 1 < n; i += 3) cdf[i] = cdf[i - 1];  // equal neighbours
    std::sort(cdf.begin(), cdf.end());
    cdf.back() = n % 4 == 0 ? std::nextafter(1.0f, 0.0f) : 1.0f;
    std::sort(cdf.begin(), cdf.end());
    std::vector<float> u{0.0f, std::nextafter(1.0f, 0.0f)};
    for (float c : cdf)
      for (float v : {c, std::nextafter(c, 0.0f), std::nextafter(c, 2.0f)})
        if (v < 1.0f) u.push_back(v);
    for (int k = 0; k < 50; ++k) u.push_back(U(gen));
    cl::Buffer bc(pr.ctx.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, n * sizeof(float),
                  cdf.data());
    cl::Buffer bu(pr.ctx.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, u.size() * sizeof(float),
                  u.data());
    cl::Buffer bo(pr.ctx.context, CL_MEM_WRITE_ONLY, u.size() * sizeof(cl_uint));
    cl::Kernel k(pr.program, "probe_cdf_search");
    lucent::test::set_args(k, 0, bc, n, bu, bo);
    lucent::test::launch_probe(pr.ctx.queue, k, u.size());
    std::vector<cl_uint> out = lucent::test::read_back<cl_uint>(pr.ctx.queue, bo, u.size());
    for (std::size_t j = 0; j < u.size(); ++j) {
      const auto below = std::upper_bound(cdf.begin(), cdf.end(), u[j]) - cdf.begin();
      const cl_uint expected = std::min<cl_uint>(static_cast<cl_uint>(below), n - 1);
      ++checked;
      if (out[j] != expected && ++wrong <= 5)
        ADD_FAILURE() << "n " << n << ", u " << u[j] << ": kernel " << out[j] << ", expected "
                      << expected;
    }
  }
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(checked, 10000u);
}
}  // namespace

}  // namespace test_kernel_light_sampling
