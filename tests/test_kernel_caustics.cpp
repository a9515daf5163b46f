// Caustics by light tracing in the kernel (integrator.caustics, docs/rendering-model.md):
// against a closed form (a point light seen in a mirror, which the path integrator alone cannot
// render), and against the path integrator without it (the two estimators split path space, so
// their expected images are equal). The kernel-versus-reference test is in
// test_kernel_vs_reference.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "lucent/compare.hpp"
#include "lucent/session.hpp"
#include "support.hpp"

namespace {

// The diffuse plane z = 0 of test_render_analytic.cpp seen straight on, lit by a point light at
// (3, 0.4, 2) and by its image in a perfect mirror, about as bright: the plane x = 3.5, facing the
// light, outside the camera's view (fov 60: the view's half-width is at most 2.9 at any height
// below the camera; the wide view makes the pinhole's cos^3 vary by a factor 2 over the film).
// Radiance leaving the plane at p: albedo/pi * I * (cos1 / r1^2 + cos2 / r2^2), the second term
// from the mirror image of the light at (4, 0.4, 2); the segment from the image to any visible
// point crosses the mirror at 1 < z < 2, inside its extent. max_depth 3 keeps only these paths
// (camera, plane, mirror, light). With caustics the mirror term comes from light tracing; without,
// it is absent. Test: expect_matches (per-pixel one-sample z-test, Sidak at alpha = 1e-3 over the
// pixels), and the image mean within 1% of the closed form (its standard error is ~0.2%).
std::string mirror_scene(bool caustics) {
  return std::string(R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 60},
    "film": {"width": 24, "height": 24},
    "integrator": {"type": "path", "max_depth": 3, "caustics": )") +
         (caustics ? "true" : "false") + R"(},
    "materials": {"white": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
                  "mirror": {"type": "mirror"}},
    "shapes": [{"type": "triangles", "material": "white",
                "positions": [[-10,-10,0],[10,-10,0],[10,10,0],[-10,10,0]],
                "indices": [0,1,2, 0,2,3]},
               {"type": "triangles", "material": "mirror",
                "positions": [[3.5,-10,0],[3.5,10,0],[3.5,10,4],[3.5,-10,4]],
                "indices": [0,1,2, 0,2,3]}],
    "lights": [{"type": "point", "position": [3.0, 0.4, 2.0], "intensity": [50, 50, 50]}]
  })";
}

double mirror_expected(int x, int y, bool caustics) {
  const double albedo = 0.6, I = 50.0, t = std::tan(30.0 * M_PI / 180.0);
  auto term = [&](double px, double py, double lx) {
    double dx = lx - px, dy = 0.4 - py, dz = 2.0, r2 = dx * dx + dy * dy + dz * dz;
    return albedo / M_PI * I * (dz / std::sqrt(r2)) / r2;
  };
  double v = 0;  // box filter: the mean over the pixel, 16x16 midpoint rule
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i) {
      double fx = x + (i + 0.5) / 16, fy = y + (j + 0.5) / 16;
      double px = (2.0 * fx / 24 - 1) * t * 5.0, py = (1 - 2.0 * fy / 24) * t * 5.0;
      v += term(px, py, 3.0) + (caustics ? term(px, py, 4.0) : 0.0);
    }
  return v / 256;
}

void check_mirror(bool caustics, int spp) {
  lucent::RenderResult r = lucent::test::render_json(mirror_scene(caustics), spp);
  lucent::test::expect_matches(r,
                               [&](int x, int y, int) { return mirror_expected(x, y, caustics); });
  double got = 0, want = 0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x)
      got += r.mean.pixel(x, y)[1], want += mirror_expected(x, y, caustics);
  EXPECT_NEAR(got / want, 1.0, 0.01) << (caustics ? "caustics" : "no caustics");
}

TEST(KernelCaustics, PointLightInAMirror) { check_mirror(true, 4096); }

// Without light tracing the path integrator cannot reach a point light through a mirror: the
// same scene renders the direct term alone (and the test above fails on it).
TEST(KernelCaustics, NoCausticsWithoutLightTracing) { check_mirror(false, 16); }

// A small sphere light over a glass sphere on a diffuse floor: the caustic under the glass is
// found by light tracing with caustics, by chance without (fireflies). Same expected image.
// Test: the difference of the two renders' means over the caustic's region and over the whole
// image, each a z-test on the variances of the means, |z| < 4 (their standard errors: the
// region's about 1.5%, dominated by the path integrator's fireflies).
TEST(KernelCaustics, SameImageAsThePathIntegrator) {
  auto scene = [](bool caustics) {
    return std::string(R"({
      "camera": {"position": [0, 6, 10], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40},
      "film": {"width": 32, "height": 24, "filter": {"type": "gaussian", "radius": 1.5}},
      "integrator": {"type": "path", "max_depth": 6, "caustics": )") +
           (caustics ? "true" : "false") + R"(},
      "materials": {
        "light": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [100, 100, 100]},
        "floor": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]},
        "glass": {"type": "dielectric", "ior": 1.5}},
      "shapes": [
        {"type": "sphere", "center": [0, 8, -6], "radius": 0.5, "material": "light"},
        {"type": "sphere", "center": [0, -1000, 0], "radius": 1000, "material": "floor"},
        {"type": "sphere", "center": [0, 1.5, 0], "radius": 1.5, "material": "glass"}]
    })";
  };
  lucent::RenderResult on = lucent::test::render_json(scene(true), 256);
  lucent::RenderResult off = lucent::test::render_json(scene(false), 4096);
  EXPECT_EQ(on.nonfinite, 0u);
  // the caustic's region, in front of the glass: rows 11-17, columns 12-20
  auto region = [](const lucent::RenderResult& r, int x0, int x1, int y0, int y1, double* var) {
    double m = 0;
    *var = 0;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        m += r.mean.pixel(x, y)[0];
        *var += r.variance.pixel(x, y)[0] / r.samples[y * 32 + x];
      }
    return m;
  };
  double v_on, v_off;
  for (auto box : {std::array<int, 4>{12, 20, 11, 17}, std::array<int, 4>{0, 31, 0, 23}}) {
    double a = region(on, box[0], box[1], box[2], box[3], &v_on);
    double b = region(off, box[0], box[1], box[2], box[3], &v_off);
    double z = (a - b) / std::sqrt(v_on + v_off);
    EXPECT_LT(std::abs(z), 4.0) << "region " << box[0] << ".." << box[1] << " x " << box[2] << ".."
                                << box[3] << ": with caustics " << a << ", without " << b;
  }
}

// ---- adaptive sampling with caustics (render_adaptive; src/render/adaptive.hpp) -------------

lucent::RenderResult render_adaptive_json(const std::string& json, double target, double budget,
                                          lucent::SamplerType sampler, std::uint32_t min_spp = 0) {
  lucent::Scene s = lucent::test::scene_from(json);
  s.integrator.sampler = sampler;
  lucent::Renderer r(lucent::test::session_options());
  r.set_scene(s);
  lucent::AdaptiveOptions ao;
  ao.target_error = target;
  ao.budget_spp = budget;
  if (min_spp) ao.min_spp = min_spp;
  r.render_adaptive(ao);
  return r.result();
}

// An adaptive render with caustics is unbiased: with a budget (counts planned from the other
// half's pilot, light paths per half), per pixel against the mirror's closed form (expect_matches:
// one-sample z-test, Sidak at alpha = 1e-3 over the pixels, on the reported variance, which
// includes the light term), and against a uniform render with caustics (compare_images: the
// two-sample z-test of Adaptive.MeanIsUnbiased), for both samplers. Power: the closed form
// without the mirror's term fails (its share is about half of every pixel's value).
TEST(KernelCaustics, AdaptiveIsUnbiased) {
  for (lucent::SamplerType sampler :
       {lucent::SamplerType::Independent, lucent::SamplerType::Sobol}) {
    SCOPED_TRACE(sampler == lucent::SamplerType::Sobol ? "sobol" : "independent");
    lucent::RenderResult a = render_adaptive_json(mirror_scene(true), 0, 512, sampler);
    EXPECT_NEAR(double(a.spp), 512, 32);
    EXPECT_GT(a.halves_relmse, 0);
    lucent::test::expect_matches(a, [](int x, int y, int) { return mirror_expected(x, y, true); });
    lucent::Scene u = lucent::test::scene_from(mirror_scene(true));
    u.integrator.sampler = sampler;
    u.integrator.seed = 0xabcdefu;
    lucent::RenderOptions o;
    o.spp = 512;
    lucent::RenderResult uniform = lucent::test::render(u, o);
    lucent::CompareResult c = lucent::compare_images(a, uniform);
    EXPECT_TRUE(c.passed) << c.summary();
    double z_max = 0;  // against the image without the caustic: far off
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x) {
        const double se = std::sqrt(a.variance.pixel(x, y)[1] / a.samples[y * 24 + x]);
        z_max =
            std::max(z_max, std::abs(a.mean.pixel(x, y)[1] - mirror_expected(x, y, false)) / se);
      }
    EXPECT_GT(z_max, 10) << "the test has no power";
  }
}

// --target-error E with caustics: the relMSE of the result against the mirror's closed form (an
// exact reference) is within a factor 2 of E, and so is the render's own estimate. Here nearly
// all the error is the light paths' (the camera paths see a point light directly, through a box
// filter: almost no variance), so a plan without the light term would stop at the pilot, far
// above E. Measured over 8 seeds and both samplers: 0.84 to 1.15 E achieved, 1.03 to 1.09 E
// estimated, about 3100 spp.
TEST(KernelCaustics, AdaptiveTargetErrorIsMet) {
  const double E = 1e-3;
  lucent::RenderResult a =
      render_adaptive_json(mirror_scene(true), E, 0, lucent::SamplerType::Independent);
  ASSERT_GT(a.spp, 0u);
  double relmse = 0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) {
      const double e = mirror_expected(x, y, true);
      for (int c = 0; c < 3; ++c) {
        const double d = a.mean.pixel(x, y)[c] - e;
        relmse += d * d / (e * e + 0.01);
      }
    }
  relmse /= 24.0 * 24 * 3;
  RecordProperty("achieved_over_target", std::to_string(relmse / E));
  RecordProperty("estimated_over_target", std::to_string(a.estimated_relmse / E));
  EXPECT_LT(relmse, 2 * E) << "mean spp " << a.spp;
  EXPECT_GT(relmse, E / 2) << "mean spp " << a.spp << ": stopped far beyond the target";
  EXPECT_LT(a.estimated_relmse, 2 * E);
  EXPECT_GT(a.estimated_relmse, E / 2);
  EXPECT_GT(a.spp, 64u) << "stopped at the pilot";
}

// What light tracing cannot do is refused with one clear line.
TEST(KernelCaustics, ThinLensRefused) {
  std::string json = mirror_scene(true);
  json.replace(json.find("\"fov\": 60"), 9,
               "\"fov\": 60, \"aperture\": 0.1, \"focus_distance\": 5");
  try {
    lucent::test::render_json(json, 1);
    FAIL() << "a thin-lens camera with caustics rendered";
  } catch (const lucent::Error& e) {
    EXPECT_NE(std::string(e.what()).find("integrator.caustics"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("pinhole"), std::string::npos) << e.what();
  }
}

}  // namespace
