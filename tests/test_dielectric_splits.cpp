// integrator.dielectric_splits (docs/rendering-model.md, "Integrators"): at the first N
// smooth-glass vertices of a camera path the kernel follows both the reflection (weight F) and the
// refraction (1 - F) instead of one chosen with those probabilities. The expected image is
// unchanged: the scalar reference never splits, so the comparisons below test the kernel's
// splitting against an independent estimator of the same image; and the noise of the lobe choice is
// gone.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "lucent/compare.hpp"
#include "lucent/reference.hpp"
#include "lucent/session.hpp"
#include "support.hpp"

namespace test_dielectric_splits {

namespace {

using lucent::RenderResult;

// A tinted glass sphere (each refraction keeps 0.6 of the light) in a constant environment, seen
// whole on a 24 x 24 film, max_depth 4. Without splitting a camera sample through the sphere is
// 1, 0.36, 0.6 x 0.6 x ... by its random lobe choices; with two splits the first two interfaces
// are followed both ways.
std::string glass_in_sky(int splits) {
  return R"({
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40},
    "film": {"width": 24, "height": 24, "filter": {"type": "box", "radius": 0.5}},
    "integrator": {"type": "path", "max_depth": 4, "dielectric_splits": )" +
         std::to_string(splits) + R"(},
    "materials": {"glass": {"type": "dielectric", "ior": 1.5, "tint": [0.6, 0.6, 0.6]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "glass"}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}]
  })";
}

// over the central 8 x 8 pixels, whose box filter's footprint lies inside the sphere's image
// (its radius is 8.2 pixels)
double variance_sum(const RenderResult& r) {
  double v = 0;
  for (int y = 8; y < 16; ++y)
    for (int x = 8; x < 16; ++x) v += r.variance.pixel(x, y)[0];
  return v;
}

// lucent compare of `r` against 1024 samples of the sphere without splitting at `seed`
lucent::CompareResult against_unsplit(const RenderResult& r, std::uint32_t seed) {
  lucent::Scene s = lucent::test::scene_from(glass_in_sky(0));
  s.integrator.seed = seed;
  lucent::RenderOptions o;
  o.spp = 1024;
  return lucent::compare_images(r, lucent::test::render(s, o));
}

// Same seed and samples, splits 2 against none: inside the sphere's image, less than 1% of the
// per-sample variance (measured: 0.05%; what is left comes from the lobes after the second
// interface). And the same image: against 1024 samples without splitting and another
// seed (lucent compare; at 64 samples some pixels' rare lobe choices are not drawn at all, which
// leaves their variance unestimated).
TEST(DielectricSplits, SameImageLessNoise) {
  RenderResult split = lucent::test::render_json(glass_in_sky(2), 64);
  RenderResult plain = lucent::test::render_json(glass_in_sky(0), 64);
  EXPECT_LT(variance_sum(split), 0.01 * variance_sum(plain))
      << variance_sum(split) << " against " << variance_sum(plain);
  const lucent::CompareResult c = against_unsplit(split, 7);
  EXPECT_TRUE(c.passed) << c.summary();
}

// An adaptive render with a target error (Renderer::render_adaptive) renders its pilot without
// splitting (docs/rendering-model.md, "Adaptive sampling"): the pilot's variances include the lobe
// choice's and so bound those of the split samples that follow. So the plan, made from the pilots
// alone, is the same with 2 splits as with none at the same seed (every pixel's count), while the
// samples beyond the pilot split (the sphere's variance falls), and the image, which mixes unsplit
// and split samples in each half, is unbiased: lucent compare against a uniform render without
// splitting and another seed.
TEST(DielectricSplits, AdaptivePilotIsUnsplit) {
  auto adaptive = [](int splits) {
    lucent::Renderer r(lucent::test::session_options());
    r.set_scene(lucent::test::scene_from(glass_in_sky(splits)));
    lucent::AdaptiveOptions ao;
    ao.target_error = 2e-4;
    r.render_adaptive(ao);
    return r.result();
  };
  const RenderResult split = adaptive(2), plain = adaptive(0);
  ASSERT_EQ(split.samples.size(), plain.samples.size());
  EXPECT_TRUE(split.samples == plain.samples) << "the plans differ: the pilot was split";
  RecordProperty("mean_spp", std::to_string(split.spp));
  EXPECT_GT(split.spp, 2 * lucent::AdaptiveOptions{}.min_spp) << "no samples beyond the pilot";
  EXPECT_LT(variance_sum(split), 0.5 * variance_sum(plain))
      << variance_sum(split) << " against " << variance_sum(plain);

  const lucent::CompareResult c = against_unsplit(split, 11);
  EXPECT_TRUE(c.passed) << c.summary();
}

// A pilot cut by an exception (a progress callback that throws, as a Python one may) leaves the
// session splitting again: after reset(), a uniform render equals a fresh session's.
TEST(DielectricSplits, AThrowingPilotLeavesTheSessionSplitting) {
  const lucent::Scene scene = lucent::test::scene_from(glass_in_sky(2));
  lucent::Renderer r(lucent::test::session_options());
  r.set_scene(scene);
  lucent::AdaptiveOptions ao;
  ao.target_error = 2e-4;
  EXPECT_THROW(r.render_adaptive(
                   ao, [](const lucent::RenderProgress&) { throw std::runtime_error("stop"); }),
               std::runtime_error);
  r.reset();
  r.render(16);
  lucent::Renderer fresh(lucent::test::session_options());
  fresh.set_scene(scene);
  fresh.render(16);
  // the same samples (to the float rounding of passes of other sizes), not another estimator's
  const RenderResult a = r.result(), b = fresh.result();
  ASSERT_EQ(a.mean.rgb.size(), b.mean.rgb.size());
  EXPECT_LT(lucent::compare_images(a, b).max_abs_error, 1e-5) << "the uniform render did not split";
}

// A target render cut after its pilot (a progress callback throws) and then resumed by another
// call renders the same samples as one uninterrupted call: the resumed call renders the rest of
// the plan with the scene's splits, and only pilot samples without.
TEST(DielectricSplits, AResumedTargetRenderEqualsAnUninterruptedOne) {
  const lucent::Scene scene = lucent::test::scene_from(glass_in_sky(2));
  lucent::SessionOptions so = lucent::test::session_options();
  so.pass_seconds = 1e-9;  // short passes: the callback runs often
  lucent::AdaptiveOptions ao;
  ao.target_error = 2e-4;
  lucent::Renderer whole(so), cut(so);
  whole.set_scene(scene);
  whole.render_adaptive(ao);
  cut.set_scene(scene);
  EXPECT_THROW(cut.render_adaptive(ao,
                                   [](const lucent::RenderProgress& p) {
                                     if (p.samples_done > 150) throw std::runtime_error("stop");
                                   }),
               std::runtime_error);
  ASSERT_LT(cut.result().spp, whole.result().spp) << "the cut came after the plan";
  ASSERT_GT(cut.result().spp, 2 * lucent::AdaptiveOptions{}.min_spp) << "cut in the pilot";
  cut.render_adaptive(ao);
  const RenderResult a = cut.result(), b = whole.result();
  EXPECT_EQ(a.samples, b.samples);
  ASSERT_EQ(a.mean.rgb.size(), b.mean.rgb.size());
  EXPECT_LT(lucent::compare_images(a, b).max_abs_error, 1e-5)
      << "the resumed samples are not the uninterrupted render's";
}

// The most splits (4: up to 16 branches per camera sample, the kernel's whole stack of waiting
// branches) through two nested glass spheres, a sphere lamp inside them, on a diffuse floor
// (the branches meet diffuse vertices, next-event estimation and light hits), against the scalar
// reference, which does not split: lucent compare (per-pixel z-test and image means).
TEST(DielectricSplits, MostSplitsMatchTheReference) {
  const std::string json = R"({
    "camera": {"position": [0, 1.5, 4], "look_at": [0, 0.6, 0], "up": [0, 1, 0], "fov": 45},
    "film": {"width": 24, "height": 18},
    "integrator": {"type": "path", "max_depth": 8, "dielectric_splits": 4},
    "materials": {"glass": {"type": "dielectric", "ior": 1.5, "tint": [0.9, 0.8, 0.7]},
                  "inner": {"type": "dielectric", "ior": 1.3},
                  "floor": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]},
                  "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [20, 20, 20]}},
    "shapes": [{"type": "sphere", "center": [0, 0.8, 0], "radius": 0.8, "material": "glass"},
               {"type": "sphere", "center": [0, 0.8, 0], "radius": 0.5, "material": "inner"},
               {"type": "sphere", "center": [0.1, 0.9, 0], "radius": 0.1, "material": "lamp"},
               {"type": "sphere", "center": [0, -100, 0], "radius": 100, "material": "floor"}],
    "lights": [{"type": "environment", "radiance": [0.2, 0.25, 0.3]}]
  })";
  lucent::Scene scene = lucent::test::scene_from(json);
  lucent::RenderOptions ko;
  ko.spp = 256;
  RenderResult kernel = lucent::test::render(scene, ko);
  scene.integrator.seed ^= 0x9e3779b9u;  // independent samples
  lucent::ReferenceOptions ro;
  ro.spp = 256;
  RenderResult reference = lucent::render_reference(scene, ro);
  lucent::CompareResult c = lucent::compare_images(kernel, reference);
  EXPECT_TRUE(c.passed) << "A = kernel, B = reference\n" << c.summary();
  EXPECT_EQ(kernel.nonfinite, 0u);
}

}  // namespace

}  // namespace test_dielectric_splits
