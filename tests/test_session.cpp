// The render session (lucent::Renderer): what a change of the scene rebuilds, progressive
// accumulation, sample ranges, cancellation, warnings, and every error of its API.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iterator>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "cl/context.hpp"
#include "cl/program_cache.hpp"
#include "lucent/reference.hpp"
#include "lucent/render.hpp"
#include "lucent/scene_builder.hpp"
#include "lucent/session.hpp"
#include "render/cancel_scope.hpp"
#include "render/device_scene.hpp"
#include "render/pack.hpp"
#include "render/resources.hpp"
#include "stability_scene.hpp"
#include "support.hpp"
#include "support/test_meshes.hpp"

namespace test_session {

namespace {

namespace fs = std::filesystem;
using lucent::Renderer;
using lucent::RenderResult;
using lucent::Scene;
using lucent::SessionStats;

const char* kScene = R"({
  "camera": {"position": [0, 1, 5], "look_at": [0, 0.5, 0], "fov": 40},
  "film": {"width": 16, "height": 12},
  "integrator": {"type": "path", "max_depth": 4, "spp": 4},
  "materials": {"w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]},
                "g": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
  "shapes": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "w"},
             {"type": "triangles", "material": "g",
              "positions": [[-5, 0, -5], [5, 0, -5], [5, 0, 5], [-5, 0, 5]],
              "indices": [0, 2, 1, 0, 3, 2]}],
  "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [20, 20, 20]}]})";

Renderer session() {
  lucent::SessionOptions o = lucent::test::session_options();
  return Renderer(o);
}

/// A session with the full kernel (every feature: the program many tests share, at `precision`),
/// for tests of set_scene's warnings, which do not depend on the kernel: a specialised kernel for
/// each variant of a scene cost those tests a cold kernel build each (1-2 s of CPU) in CI.
Renderer full_kernel_session(lucent::Precision precision = lucent::Precision::Float) {
  Renderer r = session();
  r.set_build_options(precision, false, false);
  return r;
}

bool same_image(const RenderResult& a, const RenderResult& b) {
  return a.mean.rgb == b.mean.rgb && a.variance.rgb == b.variance.rgb && a.samples == b.samples;
}

/// The same samples summed in other passes: equal up to float summation order (each pass sums
/// its samples in float on the device before the host adds the passes in double).
void expect_same_samples(const RenderResult& a, const RenderResult& b) {
  ASSERT_EQ(a.samples, b.samples);
  ASSERT_EQ(a.mean.rgb.size(), b.mean.rgb.size());
  double worst = 0;
  for (size_t i = 0; i < a.mean.rgb.size(); ++i)
    worst = std::max(
        worst, double(std::abs(a.mean.rgb[i] - b.mean.rgb[i])) / (1e-3 + std::abs(a.mean.rgb[i])));
  EXPECT_LT(worst, 1e-5);
}

using lucent::test::error_of;

uint64_t kernel_builds(const SessionStats& s) { return s.kernel_compiles + s.kernel_cache_loads; }

// Moving the camera re-renders without rebuilding the BVH or the kernel; only the launch
// parameters change, no scene buffer is uploaded.
TEST(Session, CameraChangeRebuildsNothing) {
  Renderer r = session();
  Scene s = lucent::test::scene_from(kScene);
  r.set_scene(s);
  r.render(2);
  RenderResult before = r.result();
  SessionStats st = r.stats();
  EXPECT_EQ(st.bvh_builds, 1u);
  EXPECT_EQ(kernel_builds(st), 1u);
  s.camera.position.x += 0.5;
  r.set_scene(s);
  EXPECT_EQ(r.spp(), 0u) << "a new camera drops the accumulation";
  r.render(2);
  SessionStats after = r.stats();
  EXPECT_EQ(after.bvh_builds, 1u);
  EXPECT_EQ(kernel_builds(after), 1u);
  EXPECT_EQ(after.kernel_reuses, st.kernel_reuses + 1);
  EXPECT_EQ(after.buffer_uploads, st.buffer_uploads) << "no scene buffer changed";
  EXPECT_EQ(after.scene_packs, 2u);
  EXPECT_FALSE(same_image(before, r.result()));
}

// set_scene(Scene&&) takes the scene instead of copying it (a large mesh or texture is held once):
// the session's scene is the one given, the caller's is left empty, and the image is the one a
// copied scene renders. Refused, it leaves the caller's scene as it was.
TEST(Session, TakenSceneIsHeldOnceAndRendersTheSame) {
  const Scene s = lucent::test::scene_from(kScene);
  Renderer copied = session();
  copied.set_scene(s);
  copied.render(2);
  Renderer taken = session();
  Scene given = s;
  taken.set_scene(std::move(given));
  EXPECT_TRUE(given.triangles.empty() && given.positions.empty() && given.spheres.empty());
  EXPECT_EQ(taken.scene().triangles.size(), s.triangles.size());
  EXPECT_EQ(taken.scene().positions, s.positions);
  taken.render(2);
  EXPECT_TRUE(same_image(copied.result(), taken.result()));
  // refused (a triangle indexing a vertex that is not there): untouched
  Scene bad = s;
  bad.triangles[0].v[2] = 99;
  const std::string msg = error_of([&] { taken.set_scene(std::move(bad)); });
  EXPECT_NE(msg.find("must index one of the"), std::string::npos) << msg;
  EXPECT_EQ(bad.triangles.size(), s.triangles.size());
  EXPECT_EQ(bad.positions, s.positions);
  EXPECT_EQ(taken.scene().triangles[0].v[2], s.triangles[0].v[2]) << "the session keeps its scene";
}

// A material's parameters are data: its buffer is uploaded again, nothing is rebuilt. A
// material of a type the kernel was not built with needs a kernel build, still not a BVH.
TEST(Session, MaterialChangesUploadDataOrBuildTheKernelButNeverTheBvh) {
  Renderer r = session();
  Scene s = lucent::test::scene_from(kScene);
  r.set_scene(s);
  SessionStats st = r.stats();
  s.materials[0].albedo = {0.2, 0.9, 0.2};
  r.set_scene(s);
  SessionStats a = r.stats();
  EXPECT_EQ(a.bvh_builds, 1u);
  EXPECT_EQ(kernel_builds(a), kernel_builds(st));
  EXPECT_EQ(a.buffer_uploads, st.buffer_uploads + 1) << "the materials buffer only";
  r.render(1);
  s.materials[0].type = lucent::MaterialType::Mirror;
  s.materials[0].specular = glm::dvec3(0.9);
  r.set_scene(s);
  SessionStats b = r.stats();
  EXPECT_EQ(b.bvh_builds, 1u);
  EXPECT_EQ(kernel_builds(b), kernel_builds(st) + 1) << "a mirror kernel";
  EXPECT_NE(r.result().build_options.find("LC_HAS_MIRROR"), std::string::npos);
  // back to diffuse: the session kept the first program
  s.materials[0].type = lucent::MaterialType::Diffuse;
  r.set_scene(s);
  EXPECT_EQ(kernel_builds(r.stats()), kernel_builds(st) + 1);
}

// Moving a primitive is a geometry change: the BVH is built again.
TEST(Session, GeometryChangeRebuildsTheBvh) {
  Renderer r = session();
  Scene s = lucent::test::scene_from(kScene);
  r.set_scene(s);
  s.spheres[0].center.y += 0.25;
  r.set_scene(s);
  EXPECT_EQ(r.stats().bvh_builds, 2u);
}

// The film's display settings and the scene's sample count do not change the image: the
// accumulation is kept. The seed does: it is dropped.
TEST(Session, DisplaySettingsKeepTheAccumulation) {
  Renderer r = session();
  Scene s = lucent::test::scene_from(kScene);
  r.set_scene(s);
  r.render(3);
  s.film.exposure = 2;
  s.film.tonemap = lucent::ToneMap::Aces;
  s.integrator.spp = 99;
  r.set_scene(s);
  EXPECT_EQ(r.spp(), 3u);
  s.integrator.seed = 7;
  r.set_scene(s);
  EXPECT_EQ(r.spp(), 0u);
}

// Passes add up: 3 + 5 samples are the 8 samples of one render (the random numbers are a
// function of the sample index; equal up to float summation order), and the one-shot
// lucent::render with the same passes gives the same image bit for bit.
TEST(Session, ProgressiveRendersAddUpExactly) {
  Scene s = lucent::test::scene_from(kScene);
  Renderer a = session();
  a.set_scene(s);
  a.render(3);
  a.render(5);
  Renderer b = session();
  b.set_scene(s);
  b.render(8);
  EXPECT_EQ(a.spp(), 8u);
  expect_same_samples(a.result(), b.result());
  lucent::RenderOptions o;
  o.spp = 8;
  EXPECT_TRUE(same_image(b.result(), lucent::test::render(s, o)));
}

// reset(A) starts the accumulation at sample index A: samples [0, 4) then [4, 8) of two
// sessions hold together what [0, 8) holds (sums of the two parts, weighted by their counts).
TEST(Session, ResetStartsAtASampleIndex) {
  Scene s = lucent::test::scene_from(kScene);
  Renderer whole = session(), low = session(), high = session();
  for (Renderer* r : {&whole, &low, &high}) r->set_scene(s);
  whole.render(8);
  low.render(4);
  high.reset(4);
  EXPECT_EQ(high.first_sample(), 4u);
  high.render(4);
  RenderResult w = whole.result(), l = low.result(), h = high.result();
  EXPECT_FALSE(same_image(l, h)) << "different samples";
  for (size_t i = 0; i < w.mean.rgb.size(); ++i) {
    size_t p = i / 3;
    double n_l = l.samples[p], n_h = h.samples[p];
    double merged = (l.mean.rgb[i] * n_l + h.mean.rgb[i] * n_h) / (n_l + n_h);
    EXPECT_NEAR(merged, w.mean.rgb[i], 1e-5 * (1 + std::abs(w.mean.rgb[i]))) << i;
  }
}

// Sample indices are 32-bit in the sampler: a render that would go past 2^32 is refused (its
// samples would repeat those of index 0 on), one that ends there is rendered, and a render by
// time stops there.
TEST(Session, SampleIndicesStopAt2To32) {
  std::vector<std::string> warnings;
  lucent::SessionOptions o = lucent::test::session_options();
  o.on_warning = [&](const std::string& m) { warnings.push_back(m); };
  Renderer r(o);
  r.set_scene(lucent::test::scene_from(kScene));
  const std::uint64_t end = std::uint64_t(1) << 32;
  r.reset(end - 4);
  EXPECT_THROW(r.render(5), lucent::Error);
  EXPECT_EQ(r.spp(), 0u) << "nothing rendered";
  r.render(3);
  EXPECT_EQ(r.spp(), 3u);
  EXPECT_TRUE(warnings.empty());
  lucent::RenderProgress p = r.render_for(5.0);
  EXPECT_EQ(p.samples_done, 1u) << "stops at 2^32";
  EXPECT_EQ(r.spp(), 4u);
  // and says so (it returned long before its time without a word)
  EXPECT_EQ(warnings, std::vector<std::string>{"render: stopped at sample index 4294967296 before "
                                               "the time limit: 2^32 is the sampler's range"});
  EXPECT_THROW(r.render(1), lucent::Error);
  // a count that wraps past 2^64 is named as given (it read "[6, 5)")
  r.reset(6);
  EXPECT_EQ(lucent::test::error_of([&] { r.render(~std::uint64_t(0)); }),
            "render: 18446744073709551615 samples from sample index 6 go past 2^32, the "
            "sampler's range (samples would repeat)");
  // the build options take the precisions there are
  EXPECT_EQ(lucent::test::error_of(
                [&] { r.set_build_options(static_cast<lucent::Precision>(7), false, true); }),
            "set_build_options: unknown precision 7");
}

// A pixel's sample count is 32-bit: an accumulation holds at most 2^32 - 1 samples per pixel. All
// of [0, 2^32) was accepted and wrapped every count to 0 (pixels without samples: a black image).
TEST(Session, PixelCountsStopBelow2To32) {
  Renderer r = session();
  r.set_scene(lucent::test::scene_from(kScene));
  const std::uint64_t end = std::uint64_t(1) << 32;
  EXPECT_EQ(lucent::test::error_of([&] { r.render(end, 0.05); }),
            "render: 4294967296 samples per pixel on top of the accumulation's 0 exceed 2^32 - 1, "
            "the most a pixel's sample count holds");
  EXPECT_EQ(r.spp(), 0u) << "nothing rendered";
  lucent::RenderProgress p = r.render(end - 1, 0.05);  // a time limit stops it long before
  EXPECT_GE(p.samples_done, 1u);
  EXPECT_THROW(r.render(end - p.samples_done), lucent::Error);
  EXPECT_EQ(r.spp(), p.samples_done);
}

TEST(Session, RenderForRendersAtLeastOnePass) {
  Renderer r = session();
  r.set_scene(lucent::test::scene_from(kScene));
  lucent::RenderProgress p = r.render_for(0.05);
  EXPECT_GT(p.samples_done, 0u);
  EXPECT_EQ(p.accumulated, r.spp());
  EXPECT_GT(r.result().seconds, 0);
}

// cancel() from another thread stops a long render after its current pass, with what it had.
TEST(Session, CancelStopsAfterThePassInProgress) {
  Renderer r = session();
  Scene s = lucent::test::scene_from(kScene);
  r.set_scene(s);
  std::atomic<int> passes{0};
  std::thread stopper;
  lucent::RenderProgress p = r.render(1000000, [&](const lucent::RenderProgress&) {
    if (++passes == 2) stopper = std::thread([&r] { r.cancel(); });
  });
  stopper.join();
  EXPECT_LT(p.samples_done, 1000000u);
  EXPECT_GT(r.spp(), 0u);
  EXPECT_TRUE(r.result().cancelled);
  // the next render starts uncancelled
  r.render(1);
  EXPECT_FALSE(r.result().cancelled);

  std::atomic<bool> flag{true};
  r.set_cancel_flag(&flag);
  lucent::RenderProgress q = r.render(1000);
  EXPECT_EQ(q.samples_done, 0u) << "a raised flag stops before the first pass";
  EXPECT_TRUE(r.result().cancelled);
}

// A cancel that comes once every sample of the call is rendered (from the last pass's progress
// callback) cuts nothing short: the render is complete, not cancelled. It was marked cancelled,
// and a convergence study dropped the finished rung.
TEST(Session, CancelAfterTheLastPassLeavesTheRenderComplete) {
  Renderer r = session();
  r.set_scene(lucent::test::scene_from(kScene));
  lucent::RenderProgress p = r.render(3, [&](const lucent::RenderProgress& q) {
    if (q.samples_done == 3) r.cancel();
  });
  EXPECT_EQ(p.samples_done, 3u);
  EXPECT_EQ(r.spp(), 3u);
  EXPECT_FALSE(r.result().cancelled);
  // with samples left to render, the render is cut short
  r.render(1000000, [&](const lucent::RenderProgress&) { r.cancel(); });
  EXPECT_LT(r.spp(), 1000003u);
  EXPECT_TRUE(r.result().cancelled);
}

/// kScene with a degenerate triangle (two equal vertices), which packing warns of.
Scene with_degenerate_triangle() {
  Scene s = lucent::test::scene_from(kScene);
  s.positions.push_back(s.positions[0]);
  lucent::Triangle t;
  t.v[0] = 0;
  t.v[1] = static_cast<int>(s.positions.size()) - 1;
  t.v[2] = 1;
  s.triangles.push_back(t);
  return s;
}

// Warnings of packing go to the session's sink, not to stderr.
TEST(Session, WarningsGoToTheSessionsSink) {
  std::vector<std::string> got;
  lucent::SessionOptions o = lucent::test::session_options();
  o.on_warning = [&](const std::string& m) { got.push_back(m); };
  Renderer r(o);
  Scene s = with_degenerate_triangle();
  r.set_scene(s);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_NE(got[0].find("skipped 1 degenerate or non-finite triangle"), std::string::npos)
      << got[0];
  // a scene without a name (built in code): the message starts with what happened
  s.path.clear();
  s.camera.position.x += 1;  // a new scene to pack
  r.set_scene(s);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[1].rfind("skipped 1 degenerate or non-finite triangle", 0), 0u) << got[1];
}

// A scene whose only lights are emissive triangles that packing skips (degenerate) has none left:
// a warning says so (the image was black after a warning of skipped triangles alone; the light
// notes, read before packing, saw the emitter). Not for a scene with a light entry, nor for an
// AOV.
TEST(Session, EmittersAllSkippedLeaveNoLightAndSaySo) {
  Scene s = lucent::test::scene_from(kScene);
  s.lights.clear();
  lucent::Material lamp;
  lamp.albedo = glm::dvec3(0);
  lamp.emission = glm::dvec3(5);
  lamp.name = "lamp";
  s.materials.push_back(lamp);
  for (const glm::dvec3& p : {glm::dvec3(0, 3, 0), glm::dvec3(1, 3, 0), glm::dvec3(2, 3, 0)})
    s.positions.push_back(p);  // collinear
  lucent::Triangle t;
  for (int k = 0; k < 3; ++k) t.v[k] = static_cast<int>(s.positions.size()) - 3 + k;
  t.material = static_cast<int>(s.materials.size()) - 1;
  s.triangles.push_back(t);
  std::vector<std::string> got;
  lucent::SessionOptions o = lucent::test::session_options();
  o.on_warning = [&](const std::string& m) { got.push_back(m); };
  Renderer r(o);
  r.set_scene(s);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_NE(got[0].find("skipped 1 degenerate"), std::string::npos) << got[0];
  EXPECT_NE(got[1].find("the scene has no light left (its emissive shapes were all skipped"),
            std::string::npos)
      << got[1];
  got.clear();
  s.integrator.type = lucent::IntegratorType::Albedo;
  Renderer aov(o);
  aov.set_scene(s);
  EXPECT_EQ(got.size(), 1u);  // (the skipped triangle only)
}

// A sink that throws (an application that makes warnings errors) fails set_scene; the same scene
// set again fails again: the warning was counted as given, and the second call passed without a
// word.
TEST(Session, AWarningTheSinkRefusedIsGivenAgain) {
  int calls = 0;
  lucent::SessionOptions o = lucent::test::session_options();
  o.on_warning = [&](const std::string& m) {
    ++calls;
    throw lucent::Error("strict: " + m);
  };
  Renderer r(o);
  Scene s = with_degenerate_triangle();
  for (int i = 1; i <= 2; ++i) {
    EXPECT_NE(error_of([&] { r.set_scene(s); }).find("strict: "), std::string::npos) << i;
    EXPECT_EQ(calls, i);
  }
}

// A call that changes the session holds it as a render does: a render, or another set_scene,
// from inside set_scene (its warning sink) is refused, as set_scene from another thread during a
// render now is (it passed the check just before the render began, and replaced the buffers
// under the render: SIGSEGV, 3 of 3 within 20 s, the concurrency tester's find). The session
// stays usable.
TEST(Session, CallsThatChangeTheSessionHoldItAsARenderDoes) {
  std::vector<std::string> errors;
  Renderer* self = nullptr;
  Scene s = lucent::test::scene_from(kScene);
  lucent::SessionOptions o = lucent::test::session_options();
  o.on_warning = [&](const std::string&) {
    errors.push_back(error_of([&] { self->render(1); }));
    errors.push_back(error_of([&] { self->set_scene(s); }));
    errors.push_back(error_of([&] { self->reset(); }));
  };
  Renderer r(o);
  self = &r;
  const Scene degenerate = with_degenerate_triangle();  // a warning while it packs
  r.set_scene(degenerate);
  ASSERT_EQ(errors.size(), 3u);
  const char* calls[] = {"render", "set_scene", "reset"};
  for (size_t i = 0; i < 3; ++i)
    EXPECT_EQ(errors[i].rfind(std::string(calls[i]) +
                                  ": a render of this session is in progress, or another call "
                                  "that changes it",
                              0),
              0u)
        << errors[i];
  r.render(2);
  EXPECT_EQ(r.spp(), 2u);
}

// A session destroyed from its own render's on_progress: the render went on in freed memory
// (SIGSEGV, or PoCL's abort on a destroyed mutex). The destructor cannot refuse: it ends the
// process with one line saying why.
TEST(SessionDeathTest, DestroyedDuringItsOwnRenderAbortsWithALine) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_DEATH(
      {
        auto r = std::make_unique<Renderer>(lucent::test::session_options());
        r->set_scene(lucent::test::scene_from(kScene));
        r->render(1000, [&](const lucent::RenderProgress&) { r.reset(); });
      },
      "lucent: a lucent::Renderer was destroyed during one of its own calls");
}

// The kernel cache directory is the session's: "off" compiles, a directory is filled and then
// read by the next session (where the driver keeps no cache of its own: PoCL with its cache off).
// image_hash covers the kernel source of the session's program. A kernel directory whose build
// failed, fixed and set again (kernel development in one session): the hash kept the first,
// broken source's, so that the session's parts did not merge with those of a fresh session on the
// same kernel (and a part of another kernel could claim it).
TEST(Session, ImageHashIsThatOfTheKernelSourceBuilt) {
  const fs::path dir = fs::path(lucent::test::temp_dir()) / "kernels";
  fs::copy(lucent::test::source_path("kernels"), dir, fs::copy_options::recursive);
  const fs::path main = dir / "megakernel.cl";
  const std::string good = lucent::test::read_file(main.string());
  ASSERT_FALSE(good.empty());
  lucent::SessionOptions o = lucent::test::session_options();
  o.kernel_dir = dir.string();
  Scene scene = lucent::parse_scene(kScene, "session.json");
  Renderer r(o);
  lucent::test::write_file(main.string(), good + "\n#error broken on purpose\n");
  EXPECT_NE(error_of([&] { r.set_scene(scene); }), "");
  lucent::test::write_file(main.string(), good);  // fixed
  r.set_scene(scene);
  Renderer fresh(o);
  fresh.set_scene(scene);
  EXPECT_EQ(r.image_hash(), fresh.image_hash());
}

// A render's on_progress may read the session, not change it: set_scene from it replaced the
// buffers and the accumulation under the render (with two devices a crash in the driver, with one
// a render of 8 spp that returned holding none of them).
TEST(Session, OnProgressMayReadTheSessionButNotChangeIt) {
  lucent::SessionOptions o = lucent::test::session_options();
  o.pass_seconds = 1e-6;  // one sample per pass: a callback after each
  Renderer r(o);
  Scene scene = lucent::parse_scene(kScene, "session.json");
  r.set_scene(scene);
  Scene moved = scene;
  moved.camera.position.x += 1;
  int calls = 0;
  std::vector<std::string> errors;
  r.render(8, [&](const lucent::RenderProgress& p) {
    ++calls;
    EXPECT_EQ(r.result().spp, p.accumulated);
    EXPECT_EQ(r.spp(), p.accumulated);
    errors.push_back(error_of([&] { r.set_scene(moved); }));
    errors.push_back(error_of([&] { r.set_camera(moved.camera); }));
    errors.push_back(error_of([&] { r.set_build_options(lucent::Precision::Float, true, true); }));
    errors.push_back(error_of([&] { r.reset(); }));
    errors.push_back(error_of([&] { r.render(1); }));
    lucent::AdaptiveOptions a;
    a.budget_spp = 8;
    errors.push_back(error_of([&] { r.render_adaptive(a); }));
    // moving the session away, or over it (the render went on in a moved or destroyed session:
    // SIGSEGV; the API tester's find)
    errors.push_back(error_of([&] { Renderer other = std::move(r); }));
    errors.push_back(error_of([&] { r = Renderer(o); }));
  });
  EXPECT_GE(calls, 1);
  ASSERT_FALSE(errors.empty());
  for (const std::string& e : errors)
    EXPECT_NE(e.find("a render of this session is in progress"), std::string::npos) << e;
  EXPECT_EQ(r.spp(), 8u);
  Renderer fresh(o);
  fresh.set_scene(scene);
  fresh.render(8);
  expect_same_samples(r.result(), fresh.result());
  r.set_scene(moved);  // between calls: works
  r.render(1);
  EXPECT_EQ(r.spp(), 1u);
}

// On PoCL with its own cache off, the session stores no entry either: PoCL gave programs made
// from one binary in two processes one directory, and one process aborted when the other
// released its program (cl/program_cache.hpp, keeps_program_binaries).
TEST(Session, CacheDirectoryIsAnOption) {
  lucent::test::ScopedEnv pocl_cache("POCL_KERNEL_CACHE", "0");
  Scene s = lucent::test::scene_from(kScene);
  lucent::SessionOptions o = lucent::test::session_options();
  o.cache_dir = "off";
  Renderer a(o);
  a.set_scene(s);
  EXPECT_EQ(a.stats().kernel_compiles, 1u);
  o.cache_dir = lucent::test::temp_dir() + "/cache";
  Renderer b(o), c(o);
  b.set_scene(s);
  EXPECT_EQ(b.stats().kernel_compiles, 1u);
  c.set_scene(s);
  const bool entries = lucent::cl_util::keeps_program_binaries(
      lucent::cl_util::Context(lucent::test::device()).device);
  EXPECT_EQ(c.stats().kernel_cache_loads, entries ? 1u : 0u);
  EXPECT_EQ(c.stats().kernel_compiles, entries ? 0u : 1u);
  EXPECT_EQ(lucent::cl_util::program_cache_usage(o.cache_dir).programs, entries ? 1 : 0);
  // nor a build lock there: a process waiting on it built the program again anyway
  int locks = 0;
  std::error_code ec;
  for (const auto& f : std::filesystem::directory_iterator(o.cache_dir, ec))
    locks += f.path().extension() == ".lock";
  if (!entries) {
    EXPECT_EQ(locks, 0);
  }
}

// Where the driver caches its own builds (PoCL with POCL_KERNEL_CACHE on, its default), the
// session leaves caching to it: no entry is written, and the next session builds from source
// (from PoCL's cache). cl/program_cache.hpp says why.
TEST(Session, DriverWithItsOwnCacheGetsNoEntries) {
  lucent::test::ScopedEnv pocl_cache("POCL_KERNEL_CACHE", nullptr);
  lucent::cl_util::Context ctx(lucent::test::device());
  if (lucent::cl_util::driver_program_cache(ctx.device).empty())
    GTEST_SKIP() << "the device's driver keeps no program cache: " << ctx.device.info.platform;
  Scene s = lucent::test::scene_from(kScene);
  lucent::SessionOptions o = lucent::test::session_options();
  o.cache_dir = lucent::test::temp_dir() + "/cache";
  Renderer a(o), b(o);
  a.set_scene(s);
  EXPECT_EQ(a.stats().kernel_compiles, 1u);
  for (const auto& e : fs::directory_iterator(o.cache_dir))  // build locks only
    EXPECT_EQ(e.path().extension(), ".lock") << e.path();
  b.set_scene(s);
  EXPECT_EQ(b.stats().kernel_compiles, 1u);
  EXPECT_EQ(b.stats().kernel_cache_loads, 0u);
  a.render(1);
  EXPECT_EQ(a.spp(), 1u);
}

// The one-shot render()'s sample budget: RenderOptions::spp 0 is the scene's integrator.spp, but
// with a time limit alone the render goes on until the limit, as the CLI's --time without --spp
// (the header said "the scene's" in both cases; a caller reading it got 84,153 spp in 1 s where
// it expected 2). The timed render stops by its cancel flag once past the scene's count.
TEST(Session, OneShotRenderWithATimeLimitAloneRendersUntilIt) {
  Scene s = lucent::test::scene_from(kScene);
  s.integrator.spp = 3;
  lucent::RenderOptions o = lucent::test::render_options();
  EXPECT_EQ(lucent::render(s, o).spp, 3u);
  std::atomic<bool> cancel{false};
  o.time_limit = 600;
  o.cancel = &cancel;
  o.on_progress = [&](const lucent::RenderProgress& p) {
    EXPECT_EQ(p.samples_target, 0u);
    if (p.samples_done > 3) cancel = true;
  };
  lucent::RenderResult r = lucent::render(s, o);
  EXPECT_GT(r.spp, 3u);
  EXPECT_TRUE(r.cancelled);
}

// Options out of range are errors, not defaults: a NaN pass duration made every pass 0 samples
// long and render() never returned; a negative spp or a NaN target fell back to the scene's.
TEST(Session, OptionsOutOfRangeAreErrors) {
  Scene s = lucent::test::scene_from(kScene);
  for (double bad : {std::nan(""), -1.0, 0.0, double(INFINITY)}) {
    lucent::SessionOptions o = lucent::test::session_options();
    o.pass_seconds = bad;
    EXPECT_THROW(Renderer r(o), lucent::Error) << bad;
  }
  auto error_of = [&](const std::function<void(lucent::RenderOptions&)>& set) {
    lucent::RenderOptions o = lucent::test::render_options();
    set(o);
    try {
      lucent::render(s, o);
    } catch (const lucent::Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of([](lucent::RenderOptions& o) { o.spp = -5; }),
            "render: RenderOptions::spp must be >= 0 (0: the scene's), got -5");
  EXPECT_EQ(error_of([](lucent::RenderOptions& o) { o.min_spp = -1; }),
            "render: RenderOptions::min_spp must be >= 0 (0: the default), got -1");
  EXPECT_EQ(error_of([](lucent::RenderOptions& o) { o.target_error = std::nan(""); }),
            "render: RenderOptions::target_error must be a finite number >= 0 (0: off), got nan");
  EXPECT_EQ(
      error_of([](lucent::RenderOptions& o) { o.target_error = -1e-3; }),
      "render: RenderOptions::target_error must be a finite number >= 0 (0: off), got -0.001");
  EXPECT_EQ(error_of([](lucent::RenderOptions& o) { o.pass_seconds = std::nan(""); }),
            "SessionOptions::pass_seconds must be a positive number of seconds, got nan");
  EXPECT_EQ(error_of([](lucent::RenderOptions& o) { o.spp = 2; }), "");
  // the API tester's finds: a pilot without a target was ignored, a precision of 5 taken for
  // float, a negative reference spp or thread count taken for the scene's or the hardware's
  EXPECT_EQ(error_of([](lucent::RenderOptions& o) { o.min_spp = 8; }),
            "render: RenderOptions::min_spp is the pilot of an adaptive render: it needs a "
            "target_error");
  EXPECT_EQ(error_of([](lucent::RenderOptions& o) { o.precision = lucent::Precision(5); }),
            "SessionOptions::precision must be Precision::Float or Precision::Double, got 5");
  lucent::ReferenceOptions ro;
  ro.spp = -1;
  EXPECT_EQ(lucent::test::error_of([&] { lucent::render_reference(s, ro); }),
            "ReferenceOptions::spp must be 0 (the scene's) or positive, got -1");
  ro.spp = 1;
  ro.threads = -1000;
  EXPECT_EQ(lucent::test::error_of([&] { lucent::render_reference(s, ro); }),
            "ReferenceOptions::threads must be 0 (the hardware's) or positive, got -1000");
}

// Sessions created at once from several threads, the process's first OpenCL calls among them:
// the ICD loader and PoCL initialise on the first platform query, and concurrent ones crashed
// (SIGSEGV) or saw no platform before lucent serialised the enumeration. Each session renders
// its scene, and the same seed gives the same image in every thread.
TEST(Session, SessionsCreatedConcurrentlyFromThreads) {
  Scene s = lucent::test::scene_from(kScene);
  constexpr int kThreads = 4;
  std::vector<std::string> errors(kThreads);
  std::vector<std::vector<float>> images(kThreads);
  std::atomic<int> ready{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i)
    threads.emplace_back([&, i] {
      ++ready;
      while (ready.load() < kThreads) std::this_thread::yield();
      try {
        Renderer r(lucent::test::session_options());
        Scene si = s;
        si.integrator.seed = static_cast<std::uint32_t>(i % 2);
        r.set_scene(si);
        r.render(2);
        images[i] = r.result().mean.rgb;
      } catch (const std::exception& e) {
        errors[i] = e.what();
      }
    });
  for (auto& t : threads) t.join();
  for (int i = 0; i < kThreads; ++i) {
    EXPECT_EQ(errors[i], "") << "thread " << i;
    EXPECT_FALSE(images[i].empty()) << "thread " << i;
  }
  EXPECT_TRUE(images[0] == images[2]);
  EXPECT_TRUE(images[1] == images[3]);
  EXPECT_FALSE(images[0] == images[1]) << "the seed changes the image";
}

// Several devices share a render's passes (here two contexts on the same device, "0,0"): the
// image is a one-device render's up to float summation order (the same samples, other passes),
// every device takes part, and their shares add up to the spp.
TEST(Session, SeveralDevicesShareTheSamples) {
  Scene s = lucent::test::scene_from(kScene);
  lucent::SessionOptions o = lucent::test::session_options();
  std::string one = std::to_string(lucent::select_device(o.device).index);
  o.device = one + "," + one;
  o.pass_seconds = 1e-4;  // many small passes, so that both devices take some
  Renderer both(o);
  ASSERT_EQ(both.devices().size(), 2u);
  both.set_scene(s);
  lucent::RenderProgress p = both.render(24);
  ASSERT_EQ(p.devices.size(), 2u);
  EXPECT_EQ(p.devices[0].samples + p.devices[1].samples, 24u);
  EXPECT_GT(p.devices[0].samples, 0u);
  EXPECT_GT(p.devices[1].samples, 0u);
  RenderResult r = both.result();
  EXPECT_EQ(r.spp, 24u);
  EXPECT_NE(r.device.find(" + "), std::string::npos) << r.device;
  EXPECT_EQ(kernel_builds(both.stats()), 2u) << "one build (or cache load) per device";
  Renderer single = session();
  single.set_scene(s);
  single.render(24);
  expect_same_samples(r, single.result());

  // a time budget and a cancel flag stop every device
  lucent::RenderProgress q = both.render_for(0.05);
  EXPECT_GT(q.samples_done, 0u);
  std::atomic<bool> flag{true};
  both.set_cancel_flag(&flag);
  EXPECT_EQ(both.render(100).samples_done, 0u);
  both.set_cancel_flag(nullptr);

  // accumulation() from on_progress while the other device's pass is under way: the samples are
  // not one range yet, and the error said a device's pass had failed
  both.reset();
  std::vector<std::string> errors;
  both.render(64, [&](const lucent::RenderProgress&) {
    const std::string e = error_of([&] { both.accumulation(); });
    if (!e.empty()) errors.push_back(e);
  });
  for (const std::string& e : errors)
    EXPECT_NE(e.find(" (another device's pass is still under way): read it once the render has "
                     "returned"),
              std::string::npos)
        << e;
  EXPECT_EQ(both.accumulation().spp, 64u);
}

// SessionStats counts set_scene() calls (scene_packs, kernel_reuses) once per call and work on
// the devices (kernel builds, buffer uploads) per device, in the same unit for a first upload and
// a later one: the first writes every scene buffer that holds data, not "1".
TEST(Session, StatsCountCallsOnceAndBuffersPerDevice) {
  Scene s = lucent::test::scene_from(kScene);
  bool reused = false;
  const lucent::render_detail::PackedScene packed =
      lucent::render_detail::pack_scene(s, nullptr, &reused);
  uint64_t buffers = 0, bytes = 0;
#define LUCENT_COUNT(name, type, ...)           \
  if (!packed.name.empty()) {                   \
    ++buffers;                                  \
    bytes += packed.name.size() * sizeof(type); \
  }
  LC_SCENE_BUFFERS(LUCENT_COUNT)
#undef LUCENT_COUNT
  ASSERT_GE(buffers, 6u) << "BVH nodes and leaves, triangles, spheres, materials, lights";

  Renderer one = session();
  one.set_scene(s);
  EXPECT_EQ(one.stats().buffer_uploads, buffers);
  EXPECT_EQ(one.stats().bytes_uploaded, bytes);

  lucent::SessionOptions o = lucent::test::session_options();
  std::string index = std::to_string(lucent::select_device(o.device).index);
  o.device = index + "," + index;
  Renderer both(o);
  ASSERT_EQ(both.devices().size(), 2u);
  both.set_scene(s);
  SessionStats st = both.stats();
  EXPECT_EQ(st.scene_packs, 1u);
  EXPECT_EQ(kernel_builds(st), 2u) << "one program per device";
  EXPECT_EQ(st.kernel_reuses, 0u);
  EXPECT_EQ(st.buffer_uploads, 2 * buffers) << "every buffer on each device";
  EXPECT_EQ(st.bytes_uploaded, 2 * bytes);

  s.camera.position.x += 0.5;
  both.set_scene(s);
  SessionStats moved = both.stats();
  EXPECT_EQ(moved.scene_packs, 2u);
  EXPECT_EQ(moved.kernel_reuses, 1u) << "one set_scene call kept the program";
  EXPECT_EQ(kernel_builds(moved), 2u);
  EXPECT_EQ(moved.buffer_uploads, st.buffer_uploads);

  s.materials[0].albedo = {0.2, 0.9, 0.2};
  both.set_scene(s);
  SessionStats changed = both.stats();
  EXPECT_EQ(changed.kernel_reuses, 2u);
  EXPECT_EQ(changed.buffer_uploads, st.buffer_uploads + 2) << "the materials buffer, twice";
  EXPECT_EQ(changed.bytes_uploaded,
            st.bytes_uploaded + 2 * packed.materials.size() * sizeof(packed.materials[0]));
}

// render_adaptive's options and the accumulation it may continue are checked: each misuse is an
// error saying what is wrong, and the accumulation in the session stays as it was.
TEST(Session, AdaptiveMisuseIsAnErrorAndLosesNothing) {
  Renderer r = session();
  r.set_scene(lucent::test::scene_from(kScene));
  auto error_of = [&](const lucent::AdaptiveOptions& o) -> std::string {
    try {
      r.render_adaptive(o);
    } catch (const lucent::Error& e) {
      return e.what();
    }
    return "";
  };
  lucent::AdaptiveOptions neither, both, nan_target, inf_budget, small_pilot, low_cap, time;
  both.target_error = 1e-3;
  both.budget_spp = 16;
  nan_target.target_error = std::nan("");
  inf_budget.budget_spp = INFINITY;
  const std::string either =
      "render_adaptive: give either a target error or a budget, a positive number";
  for (const lucent::AdaptiveOptions* o : {&neither, &both, &nan_target, &inf_budget})
    EXPECT_EQ(error_of(*o), either);
  small_pilot.budget_spp = low_cap.budget_spp = time.budget_spp = 16;
  small_pilot.min_spp = 2;
  EXPECT_EQ(error_of(small_pilot),
            "render_adaptive: expected 4 <= min_spp and its pilot (min_spp rounded up to even, 2) "
            "<= max_spp, got 2 and 16384");
  low_cap.min_spp = 64;
  low_cap.max_spp = 32;
  EXPECT_EQ(error_of(low_cap),
            "render_adaptive: expected 4 <= min_spp and its pilot (min_spp rounded up to even, 64) "
            "<= max_spp, got 64 and 32");
  // an odd pilot rounds up to two halves of 3: 6 samples, which a cap of 5 cannot hold (it
  // rendered 6 per pixel)
  low_cap.min_spp = 5;
  low_cap.max_spp = 5;
  EXPECT_EQ(error_of(low_cap),
            "render_adaptive: expected 4 <= min_spp and its pilot (min_spp rounded up to even, 6) "
            "<= max_spp, got 5 and 5");
  for (double t : {-1.0, double(NAN), double(INFINITY)}) {
    time.max_seconds = t;
    EXPECT_EQ(error_of(time),
              "render_adaptive: the time limit must be a non-negative number of seconds");
  }

  // a uniform render is not continued adaptively, and keeps its samples
  r.render(4);
  lucent::AdaptiveOptions ok;
  ok.budget_spp = 16;
  ok.min_spp = 8;
  EXPECT_NE(error_of(ok).find("the accumulation holds a uniform render's samples"),
            std::string::npos);
  EXPECT_EQ(r.result().spp, 4u);
  // nor an adaptive render uniformly, or with another pilot
  r.reset();
  r.render_adaptive(ok);
  const lucent::RenderResult adaptive = r.result();
  EXPECT_GT(adaptive.halves_relmse, 0.0);
  try {
    r.render(1);
    ADD_FAILURE() << "an adaptive render continued uniformly";
  } catch (const lucent::Error& e) {
    EXPECT_NE(std::string(e.what()).find("the accumulation is an adaptive render's"),
              std::string::npos)
        << e.what();
  }
  lucent::AdaptiveOptions other_pilot = ok;
  other_pilot.budget_spp = 32;
  other_pilot.min_spp = 16;
  EXPECT_EQ(error_of(other_pilot),
            "render_adaptive: min_spp 16 differs from the adaptive render in progress (call "
            "reset() first)");
  EXPECT_EQ(r.result().spp, adaptive.spp);
  EXPECT_TRUE(r.result().mean.rgb == adaptive.mean.rgb);
}

TEST(Session, ErrorsAreLucentErrors) {
  Renderer r = session();
  EXPECT_THROW(r.render(1), lucent::Error) << "no scene yet";
  EXPECT_THROW(r.result(), lucent::Error);
  EXPECT_THROW(r.scene(), lucent::Error);
  r.set_scene(lucent::test::scene_from(kScene));
  EXPECT_THROW(r.render(0), lucent::Error);
  EXPECT_THROW(r.render_for(0), lucent::Error);
  EXPECT_THROW(r.render_for(std::nan("")), lucent::Error);
  EXPECT_THROW(r.render(0, 0), lucent::Error);
  EXPECT_THROW(r.render(1, -1), lucent::Error);
  EXPECT_THROW(r.reset(1ull << 32), lucent::Error);
  lucent::SessionOptions bad = lucent::test::session_options();
  bad.device = "no such device at all";
  EXPECT_THROW(Renderer{bad}, lucent::Error);
  bad.device = "0,";
  EXPECT_THROW(Renderer{bad}, lucent::Error);
  bad.device = "0,no such device at all";
  EXPECT_THROW(Renderer{bad}, lucent::Error);
  Scene huge = lucent::test::scene_from(kScene);
  huge.film.width = huge.film.height = 1 << 20;
  try {
    r.set_scene(huge);
    FAIL() << "a 2^20 x 2^20 film was accepted";
  } catch (const lucent::Error& e) {
    EXPECT_NE(std::string(e.what()).find("1048576x1048576 film"), std::string::npos) << e.what();
  }
  // the session still renders its previous scene
  r.render(1);
  EXPECT_EQ(r.result().mean.width, 16);
}

}  // namespace

// A set_scene that fails after it has begun to change the device (an allocation failing
// part-way through the upload, simulated by ScopedUploadFault) leaves buffers that match neither
// scene. The session drops them: rendering is refused until a set_scene succeeds, the image
// rendered before stays readable, and going back to the first scene uploads it again (it once
// kept the device's half-new buffers because the host's record still said "first scene", and
// rendered the first scene's samples with the second scene's materials).
TEST(Session, FailedUploadDropsTheDeviceScene) {
  Scene s1 = lucent::test::scene_from(kScene);
  Scene s2 = s1;
  s2.materials[0].albedo = glm::dvec3(0.1, 0.9, 0.1);
  Renderer r = session();
  r.set_scene(s1);
  r.render(4);
  const RenderResult before = r.result();
  {
    lucent::render_detail::ScopedUploadFault fault;
    std::string msg = error_of([&] { r.set_scene(s2); });
    EXPECT_NE(msg.find("clCreateBuffer (injected by a test)"), std::string::npos) << msg;
  }
  std::string msg = error_of([&] { r.render(1); });
  EXPECT_NE(msg.find("render: the last set_scene failed, so the devices hold no scene"),
            std::string::npos)
      << msg;
  EXPECT_TRUE(same_image(r.result(), before));
  r.set_scene(s1);
  r.render(4);
  Renderer fresh = session();
  fresh.set_scene(s1);
  fresh.render(4);
  EXPECT_TRUE(same_image(r.result(), fresh.result()));
  // set_build_options refused by the same failure keeps the options the programs were built with
  {
    lucent::render_detail::ScopedUploadFault fault;
    EXPECT_NE(error_of([&] { r.set_build_options(lucent::Precision::Float, true, true); }), "");
  }
  EXPECT_FALSE(r.options().fast_math);
}

// An adaptive render's device shares add up to its samples per pixel: the jobs of its later
// rounds hold fewer samples than the film has pixels, and each one's share was once truncated
// to 0 samples per pixel.
TEST(Session, AdaptiveDeviceSharesCountEverySample) {
  Renderer r = session();
  r.set_scene(lucent::test::scene_from(kScene));
  lucent::AdaptiveOptions ao;
  ao.budget_spp = 24;
  ao.min_spp = 8;
  lucent::RenderProgress p = r.render_adaptive(ao);
  const RenderResult res = r.result();
  ASSERT_EQ(p.devices.size(), 1u);
  ASSERT_EQ(res.devices.size(), 1u);
  EXPECT_GE(p.accumulated, 20u);
  EXPECT_EQ(p.devices[0].samples, p.accumulated);
  EXPECT_EQ(res.devices[0].samples, p.accumulated);
}

// A moved-from Renderer holds no session: its methods throw lucent::Error (spp() and every other
// call dereferenced a null pointer, SIGSEGV), and the Renderer it moved to renders.
TEST(Session, MovedFromRendererThrows) {
  Renderer a = session();
  a.set_scene(lucent::test::scene_from(kScene));
  Renderer b(std::move(a));
  const std::string moved = "this lucent::Renderer was moved from: it holds no session";
  EXPECT_EQ(lucent::test::error_of([&] { (void)a.spp(); }), moved);
  EXPECT_EQ(lucent::test::error_of([&] { a.render(1); }), moved);
  EXPECT_EQ(lucent::test::error_of([&] { (void)a.result(); }), moved);
  EXPECT_EQ(lucent::test::error_of([&] { a.set_scene(lucent::test::scene_from(kScene)); }), moved);
  EXPECT_EQ(lucent::test::error_of([&] { a.cancel(); }), moved);
  b.render(1);
  EXPECT_EQ(b.spp(), 1u);
  a = std::move(b);  // assigned again, it renders
  a.render(1);
  EXPECT_EQ(a.spp(), 2u);
}

// A light-transport render of a scene with nothing that emits is black: a warning says so (it
// was silent). The AOVs need no light and get none.
TEST(Session, SceneWithoutLightWarns) {
  Scene dark = lucent::test::scene_from(kScene);
  dark.lights.clear();
  Renderer r = full_kernel_session();
  {
    lucent::test::CaptureWarnings warnings;
    r.set_scene(dark);
    EXPECT_EQ(warnings.count("the scene has no light (no light entry, no emissive material): the "
                             "image is black"),
              1)
        << warnings.dump();
  }
  {  // the reference says so too (it was silent)
    lucent::test::CaptureWarnings warnings;
    dark.film.width = dark.film.height = 2;
    lucent::ReferenceOptions ro;
    ro.spp = 1;
    lucent::render_reference(dark, ro);
    EXPECT_EQ(warnings.count("the scene has no light"), 1) << warnings.dump();
  }
  dark.integrator.type = lucent::IntegratorType::Albedo;
  lucent::test::CaptureWarnings warnings;
  r.set_scene(dark);
  EXPECT_EQ(warnings.all().size(), 0u) << warnings.dump();
}

// Whitted and direct light surfaces by point lights alone: a scene lit by an environment or by
// emissive shapes rendered black but for what the camera sees emit, without a word (the visual
// review: scenes/course.json with --integrator whitted, 4074 of 4096 pixels black). A warning
// says so, from the session and the reference; none with a point light or for path.
TEST(Session, WhittedAndDirectWithoutAPointLightWarn) {
  Scene s = lucent::test::scene_from(kScene);
  s.film.width = s.film.height = 2;
  s.lights.front().type = lucent::LightType::Environment;
  s.lights.front().radiance = glm::dvec3(1.0);
  const std::string note =
      " lights surfaces by point lights alone, and the scene has no point light that emits: its "
      "emissive shapes and environment show only where seen, and its non-specular surfaces are "
      "black (path lights them)";
  Renderer r = full_kernel_session();
  lucent::ReferenceOptions ro;
  ro.spp = 1;
  for (const auto type : {lucent::IntegratorType::Whitted, lucent::IntegratorType::Direct}) {
    s.integrator.type = type;
    const std::string name = type == lucent::IntegratorType::Whitted ? "whitted" : "direct";
    {
      lucent::test::CaptureWarnings warnings;
      r.set_scene(s);
      EXPECT_EQ(warnings.count("integrator " + name + note), 1) << warnings.dump();
    }
    lucent::test::CaptureWarnings warnings;
    lucent::render_reference(s, ro);
    EXPECT_EQ(warnings.count("integrator " + name + note), 1) << warnings.dump();
  }
  // with a point light that emits (for either integrator), or with path: nothing said, by a new
  // session (one gives each note of a scene once) or the reference
  std::vector<Scene> quiet;
  for (const auto type : {lucent::IntegratorType::Whitted, lucent::IntegratorType::Direct}) {
    quiet.push_back(s);
    quiet.back().integrator.type = type;
    quiet.back().lights.push_back(lucent::test::scene_from(kScene).lights.front());
  }
  quiet.push_back(s);
  quiet.back().integrator.type = lucent::IntegratorType::Path;
  for (const Scene& t : quiet) {
    {
      lucent::test::CaptureWarnings warnings;
      Renderer fresh = full_kernel_session();
      fresh.set_scene(t);
      EXPECT_EQ(warnings.count("point lights alone"), 0) << warnings.dump();
    }
    lucent::test::CaptureWarnings warnings;
    lucent::render_reference(t, ro);
    EXPECT_EQ(warnings.count("point lights alone"), 0) << warnings.dump();
  }
}

// An emission or environment radiance above sqrt(FLT_MAX) (about 1.84e19) makes samples whose
// square overflows a float, which the kernel and the reference drop: the scene's first such
// radiance is named before either renders (the lamp's pixels came out black, with a count of
// non-finite samples and no word of why). A point light's intensity reaches a pixel divided by a
// squared distance (1e20 at 1000 renders without a dropped sample): it is named when the
// geometry's box lies within the distance where its squares overflow (1e30 rendered black
// without a word).
TEST(Session, RadianceBeyondFloatSquaresWarns) {
  Scene s = lucent::test::scene_from(kScene);
  s.film.width = s.film.height = 2;
  const std::string hot =
      "/lights/0/radiance 1e+20 is above 1.84e+19, where a sample's square "
      "overflows a float: such samples are dropped as non-finite (lower it "
      "and raise film.exposure)";
  lucent::Light sky;
  sky.type = lucent::LightType::Environment;
  sky.radiance = glm::dvec3(1e20, 1, 1);
  s.lights.insert(s.lights.begin(), sky);
  lucent::ReferenceOptions ro;
  ro.spp = 1;
  {
    lucent::test::CaptureWarnings warnings;
    lucent::render_detail::pack_scene(s);  // (its warnings: no kernel built)
    EXPECT_EQ(warnings.count(hot), 1) << warnings.dump();
  }
  {
    lucent::test::CaptureWarnings warnings;
    lucent::render_reference(s, ro);
    EXPECT_EQ(warnings.count(hot), 1) << warnings.dump();
  }
  s.lights[0].radiance = glm::dvec3(1e19, 1, 1);  // below: nothing said
  s.materials[0].emission = glm::dvec3(0, 2e19, 0);
  {
    lucent::test::CaptureWarnings warnings;
    lucent::render_detail::pack_scene(s);  // (its warnings: no kernel built)
    EXPECT_EQ(warnings.count("material '" + s.materials[0].name + "': emission 2e+19 is above"), 1)
        << warnings.dump();
  }
  s.materials[0].emission = glm::dvec3(0);
  // a map: its scale times its brightest texel (1e10 x 4e9)
  s.textures.push_back(lucent::texture_from_rgba(2, 1, {1, 1, 1, 1, 1, 4e9f, 1, 1}));
  s.lights[0] = lucent::environment_map(static_cast<int>(s.textures.size()) - 1, 1e10);
  {
    lucent::test::CaptureWarnings warnings;
    lucent::render_detail::pack_scene(s);  // (its warnings: no kernel built)
    EXPECT_EQ(warnings.count("/lights/0/scale (times the map's brightest texel) 4e+19 is above"), 1)
        << warnings.dump();
  }
  s.lights.erase(s.lights.begin());
  for (lucent::Light& l : s.lights)
    if (l.type == lucent::LightType::Point) l.intensity = glm::dvec3(1e20);
  {
    // (its squares overflow within 2.33 of it; the geometry's box is 3 away)
    lucent::test::CaptureWarnings warnings;
    lucent::render_detail::pack_scene(s);  // (its warnings: no kernel built)
    EXPECT_EQ(warnings.count("is above 1.84e+19"), 0) << warnings.dump();
  }
  for (lucent::Light& l : s.lights)
    if (l.type == lucent::LightType::Point) l.intensity = glm::dvec3(1e30);
  lucent::test::CaptureWarnings warnings;
  lucent::render_detail::pack_scene(s);
  EXPECT_EQ(warnings.count("/intensity 1e+30 is above 1.84e+19, where a sample's square "
                           "overflows a float within a distance of about 2.33e+05 of it"),
            1)
      << warnings.dump();
}

// Lights that all send out nothing render a black image as well: zero intensities and
// radiances, an environment map scaled by 0 or black in the channels its scale keeps. That was
// silent (a reviewer's all-black map and zero point lights); a light that emits in any channel,
// or any emissive shape, keeps the warning away.
TEST(Session, SceneWhoseLightsEmitNothingWarns) {
  const char* kMessage =
      "every light of the scene emits nothing (an intensity, radiance or scale of 0, or a black "
      "environment map): the image is black";
  auto warnings_for = [&](const Scene& scene) {
    Renderer r = full_kernel_session();  // a session says each warning once
    lucent::test::CaptureWarnings warnings;
    r.set_scene(scene);
    return warnings.count(kMessage);
  };
  Scene base = lucent::test::scene_from(kScene);
  base.lights[0].intensity = glm::dvec3(0);
  lucent::Light env;
  env.type = lucent::LightType::Environment;
  base.lights.push_back(env);  // radiance 0
  EXPECT_EQ(warnings_for(base), 1);
  {  // and the reference (it was silent)
    lucent::test::CaptureWarnings warnings;
    Scene small = base;
    small.film.width = small.film.height = 2;
    lucent::ReferenceOptions ro;
    ro.spp = 1;
    lucent::render_reference(small, ro);
    EXPECT_EQ(warnings.count(kMessage), 1) << warnings.dump();
  }

  // a 2x1 map, red in one texel, green 0, blue 0 in both
  lucent::Texture t;
  t.path = "red.pfm";
  t.width = 2;
  t.height = 1;
  t.rgba = {0, 0, 0, 1, 3, 0, 0, 1};
  Scene mapped = base;
  mapped.textures.push_back(t);
  mapped.lights[1].type = lucent::LightType::EnvironmentMap;
  mapped.lights[1].texture = 0;
  mapped.lights[1].radiance = glm::dvec3(0, 1, 1);  // keeps green and blue only: black
  EXPECT_EQ(warnings_for(mapped), 1);
  mapped.lights[1].radiance = glm::dvec3(1, 0, 0);  // the red texel
  EXPECT_EQ(warnings_for(mapped), 0);
  mapped.textures[0].rgba[4] = 0;  // an all-black map, whatever its scale
  EXPECT_EQ(warnings_for(mapped), 1);

  Scene some = base;
  some.lights[0].intensity = glm::dvec3(0, 0, 1e-30);
  EXPECT_EQ(warnings_for(some), 0);
  Scene shape = base;  // an emissive sphere is a light that emits
  shape.materials[0].emission = glm::dvec3(1);
  EXPECT_EQ(warnings_for(shape), 0);
}

// The camera and the scene are stored in float with either precision: a pixel spanning fewer
// than 4 float steps at the look-at distance renders their rounding (at fov 1e-4 degrees a
// reviewer's sphere silhouette came out in steps of whole pixels, its mean 13.9 standard errors
// from the reference's, 17.3 with --precision double), which a warning now says. fov 1e-2
// degrees here spans 120 steps, a camera and its scene 1e8 from the origin 0.03. The distance is
// the scene's bounds' when they are farther than the look-at (a look-at just ahead of a camera far
// from what it sees warned).
TEST(Session, CameraFinerThanFloatWarns) {
  Renderer r = session();
  const std::string what = "float steps of the coordinates at the look-at distance";
  const Scene base = lucent::test::scene_from(kScene);
  // the camera (and with `scene`, the scene) moved by x
  auto warnings_for = [&](double fov, double x, bool scene = true) {
    Scene s = base;
    s.camera.fov_degrees = fov;
    s.camera.position.x += x;
    s.camera.look_at.x += x;
    if (scene) {
      for (glm::dvec3& p : s.positions) p.x += x;
      s.spheres[0].center.x += x;
    }
    lucent::test::CaptureWarnings warnings;
    r.set_scene(s);
    int n = 0;
    for (const std::string& w : warnings.all()) n += w.find(what) != std::string::npos;
    return n;
  };
  EXPECT_EQ(warnings_for(40, 0), 0);
  EXPECT_EQ(warnings_for(1e-2, 0), 0);
  EXPECT_EQ(warnings_for(1e-4, 0), 1);
  EXPECT_EQ(warnings_for(1e-4, 0), 0);  // once per session (an AOV render said it per AOV)
  EXPECT_EQ(warnings_for(40, 1e8), 1);
  // a look-at 5 ahead of a camera whose scene is 1e8 away: its pixels there span many steps
  EXPECT_EQ(warnings_for(40, 1e8, false), 0);
}

// A surface within a few float steps of the camera: the camera's stored (float) position may fall
// on it or past it, with either precision, and the surface is not seen. A wall 0.0002 in front of
// a camera at x = 1e4 (floats 0.001 apart there) was sky in both precisions, without a word,
// where the reference sees the wall. Said now; not for the wall at 0.5, nor for a camera at the
// origin, nor for one far outside the scene's bounds.
TEST(Session, SurfaceWithinFloatStepsOfTheCameraWarns) {
  const std::string what = "camera: a surface lies within ";
  auto warnings_for = [&](double x, double gap) {
    char json[1024];
    std::snprintf(json, sizeof json, R"({
      "camera": {"position": [%.17g, 0, 0], "look_at": [%.17g, 0, 0], "up": [0, 1, 0], "fov": 60},
      "film": {"width": 8, "height": 8},
      "materials": {"wall": {"type": "diffuse", "albedo": [0.3, 0.3, 0.3]}},
      "shapes": [{"type": "triangles", "material": "wall",
                  "positions": [[%.17g, -50, -50], [%.17g, 50, -50], [%.17g, 50, 50], [%.17g, -50, 50]],
                  "indices": [0, 1, 2, 0, 2, 3]}],
      "lights": [{"type": "environment", "radiance": [1, 1, 1]}]})",
                  x, x - 200, x - gap, x - gap, x - gap, x - gap);
    // (pack_scene's warning, the same for either precision: no kernel is built)
    lucent::test::CaptureWarnings warnings;
    lucent::render_detail::pack_scene(lucent::test::scene_from(json));
    return warnings.count(what);
  };
  EXPECT_EQ(warnings_for(10000.0004, 0.0002), 1);
  EXPECT_EQ(warnings_for(10000.0004, 0.5), 0);
  EXPECT_EQ(warnings_for(0.0004, 0.0002), 0);
  EXPECT_EQ(warnings_for(10000.0004, -1e3), 0);  // the wall far behind the camera
}

// In float precision, rays leave surfaces offset by their rounding, which scales with their
// primitive's coordinates: a warning says when that is large against the scene's small features
// (a ground triangle of 1e6 under a sphere of 0.01 rendered 16% too dark, image-mean z -84
// against the reference) or when the scene lies 100 times its size from the origin (a box of
// size 2 at 1e4 leaked the sky along its inner edges). Not in double precision, which renders
// both right, nor for this test's scene.
/// The warnings containing `what` that a new session gives for scene s at `precision`.
int warnings_containing(const Scene& s, lucent::Precision precision, const std::string& what) {
  Renderer r = full_kernel_session(precision);
  lucent::test::CaptureWarnings warnings;
  r.set_scene(s);
  int n = 0;
  for (const std::string& w : warnings.all()) n += w.find(what) != std::string::npos;
  return n;
}

TEST(Session, FloatRoundingLargeAgainstTheSceneWarns) {
  const std::string what = "in float precision, rays leave surfaces offset by their rounding";
  auto warnings_for = [&](const Scene& s, lucent::Precision precision) {
    return warnings_containing(s, precision, what);
  };
  const Scene plain = lucent::test::scene_from(kScene);
  EXPECT_EQ(warnings_for(plain, lucent::Precision::Float), 0);
  Scene ground = plain;  // the floor quad made 1e6 wide, the sphere 0.01
  for (glm::dvec3& p : ground.positions) p *= 2e5;
  ground.spheres[0].radius = 0.01;
  EXPECT_EQ(warnings_for(ground, lucent::Precision::Float), 1);
  EXPECT_EQ(warnings_for(ground, lucent::Precision::Double), 0);
  // a sphere of 0.1 resting on a floor of +-1e4 (offsets of 0.0095, 1/10.5 of it): its contact
  // shadow rendered up to 1.8 times too bright (image-mean z 13 at 1024 spp), silently under
  // the 1/8 first chosen; on a floor of +-2e3 (1/52) it is not said
  for (const double floor : {1e4, 2e3}) {
    Scene contact = plain;
    for (glm::dvec3& p : contact.positions) p *= floor / 5;  // (kScene's floor spans +-5)
    contact.spheres.resize(1);
    contact.spheres[0].radius = 0.05;
    contact.spheres[0].center = glm::dvec3(0, contact.positions[0].y + 0.05, 0);
    EXPECT_EQ(warnings_for(contact, lucent::Precision::Float), floor > 5e3 ? 1 : 0) << floor;
  }
  Scene far = plain;  // the whole scene (size about 14) moved to 1e5
  for (glm::dvec3& p : far.positions) p.x += 1e5;
  far.spheres[0].center.x += 1e5;
  EXPECT_EQ(warnings_for(far, lucent::Precision::Float), 1);
  far = plain;  // at 1e3: 70 times its size
  for (glm::dvec3& p : far.positions) p.x += 1e3;
  far.spheres[0].center.x += 1e3;
  EXPECT_EQ(warnings_for(far, lucent::Precision::Float), 0);
  // at 1e4, 700 times its size: under the 1000 times first chosen, this scene as a sphere light
  // over a plane rendered 0.8% bright (image-mean z 7.9 at 1024 spp), silently
  far = plain;
  for (glm::dvec3& p : far.positions) p.x += 1e4;
  far.spheres[0].center.x += 1e4;
  EXPECT_EQ(warnings_for(far, lucent::Precision::Float), 1);
  // a sphere of non-finite centre is never hit: it counted as a coordinate of inf ("offset by
  // their rounding, up to inf here"), the Python review's find
  Scene odd = plain;
  odd.spheres.push_back(odd.spheres[0]);
  odd.spheres.back().center.x = INFINITY;
  EXPECT_EQ(warnings_for(odd, lucent::Precision::Float), 0);
}

// Both precisions store the scene's coordinates in float: a ground sphere of radius 1e7 whose
// centre, -9999999.7, rounds to -1e7 moves the ground 0.3 under kScene's sphere of 0.5 (which then
// floats above it), and double rendered that without a word (image-mean z -24 against the
// reference), after float's warning had recommended double. Said in both precisions now; not for
// a centre that floats hold, nor for kScene.
TEST(Session, StoredRoundingLargeAgainstTheSceneWarnsInBothPrecisions) {
  const std::string what = "the scene's coordinates are stored in float in either precision";
  const Scene plain = lucent::test::scene_from(kScene);
  for (const auto precision : {lucent::Precision::Float, lucent::Precision::Double}) {
    SCOPED_TRACE(lucent::precision_name(precision));
    EXPECT_EQ(warnings_containing(plain, precision, what), 0);
    for (const double centre : {-9999999.7, -1e7}) {
      Scene ground = plain;
      ground.spheres.push_back(ground.spheres[0]);
      ground.spheres.back().center = glm::dvec3(0, centre, 0);
      ground.spheres.back().radius = 1e7;
      EXPECT_EQ(warnings_containing(ground, precision, what), centre == -1e7 ? 0 : 1) << centre;
    }
  }
}

// An emitter below 1e-18 of the scene's size: light sampling's density (1 / its solid angle)
// overflows float, and its light is lost in either precision (a sphere light of radius 1e-20 and
// emission 1e38 rendered black, the reference 5e-4, without a word; the BVH and lights
// campaigns). Said now; not for a sphere light of 1e-3.
TEST(Session, EmittersTooSmallForLightSamplingWarn) {
  const std::string what = "subtends less than light sampling's float density can hold";
  for (const double radius : {1e-20, 1e-3}) {
    Scene s = lucent::test::scene_from(kScene);
    lucent::Material lamp = s.materials[0];
    lamp.name = "lamp";
    lamp.emission = {1, 1, 1};
    s.materials.push_back(lamp);
    s.spheres.push_back({{0, 2, 0}, radius, static_cast<int>(s.materials.size()) - 1});
    EXPECT_EQ(warnings_containing(s, lucent::Precision::Float, what), radius < 1e-18 ? 1 : 0)
        << radius;
  }
}

// In float precision the triangle test's products of three coordinate differences underflow in a
// tiny scene (a Cornell box scaled by 1e-15 rendered half as bright, by 1e-16 black, without a
// word; double renders it right): a warning says so below a size of 1e-10, in float only.
TEST(Session, FloatTinySceneWarns) {
  const std::string what = "in float precision, the intersection tests multiply coordinate";
  auto warnings_for = [&](double scale, lucent::Precision precision) {
    Scene s = lucent::test::map_positions(lucent::test::scene_from(kScene),
                                          [&](glm::dvec3 p) { return scale * p; });
    for (auto& sp : s.spheres) sp.radius *= scale;
    return warnings_containing(s, precision, what);
  };
  EXPECT_EQ(warnings_for(1e-12, lucent::Precision::Float), 1);
  EXPECT_EQ(warnings_for(1e-12, lucent::Precision::Double), 0);
  EXPECT_EQ(warnings_for(1e-8, lucent::Precision::Float), 0);
  EXPECT_EQ(warnings_for(1, lucent::Precision::Float), 0);
}

// A sphere light cut by another surface into a thin part, against float's rounding there: a
// smallpt-style room (walls of spheres of radius 1e5, offsets of 0.19 near them) whose lamp of
// radius 600 pokes 0.27 through the ceiling rendered 2% bright in float (1.2% once the light's own
// shadow-ray margin was bounded), image-mean z 8 against the reference, without a word: neither
// the features (the 10th percentile of primitive sizes, 33) nor the scene's size (its bounds hold
// the walls) are small against the offsets. Said now; not in double, not for the same room with a
// small lamp hanging free (nothing cut), nor for a ceiling of triangles near the origin.
TEST(Session, SphereLightCutThinAgainstFloatRoundingWarns) {
  const std::string what = "is cut by another surface into a part only";
  auto warnings_for = [&](const Scene& s, lucent::Precision precision) {
    return warnings_containing(s, precision, what);
  };
  auto room = [](const char* lamp, bool sphere_ceiling) {
    const std::string ceiling =
        sphere_ceiling
            ? R"({"type": "sphere", "center": [50, -99918.4, 81.6], "radius": 1e5, "material": "white"})"
            : R"({"type": "triangles", "material": "white", "indices": [0,1,2, 0,2,3],
                 "positions": [[-50,81.6,-50],[150,81.6,-50],[150,81.6,250],[-50,81.6,250]]})";
    return lucent::test::scene_from(std::string(R"({
      "camera": {"position": [50, 52, 165], "look_at": [50, 47.7, 65], "fov": 75},
      "film": {"width": 16, "height": 16},
      "materials": {"white": {"type": "diffuse", "albedo": [0.75, 0.75, 0.75]},
                    "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [12, 12, 12]}},
      "shapes": [
        {"type": "sphere", "center": [100001, 40.8, 81.6], "radius": 1e5, "material": "white"},
        {"type": "sphere", "center": [-99901, 40.8, 81.6], "radius": 1e5, "material": "white"},
        {"type": "sphere", "center": [50, 40.8, 1e5], "radius": 1e5, "material": "white"},
        {"type": "sphere", "center": [50, 1e5, 81.6], "radius": 1e5, "material": "white"},
        {"type": "sphere", "center": [27, 16.5, 47], "radius": 16.5, "material": "white"},
        {"type": "sphere", "center": [73, 16.5, 78], "radius": 16.5, "material": "white"},
        )") + ceiling + ", " + lamp +
                                    "]}");
  };
  const char* poking = R"({"type": "sphere", "center": [50, 681.33, 81.6], "radius": 600,
                           "material": "lamp"})";
  const char* hanging = R"({"type": "sphere", "center": [50, 70, 81.6], "radius": 5,
                            "material": "lamp"})";
  EXPECT_EQ(warnings_for(room(poking, true), lucent::Precision::Float), 1);
  EXPECT_EQ(warnings_for(room(poking, true), lucent::Precision::Double), 0);  // +0.5%, z 2
  EXPECT_EQ(warnings_for(room(hanging, true), lucent::Precision::Float), 0);
  // the ceiling a quad of +-100 around the room: offsets of 2.4e-4, the lamp's own margin 2.4e-3
  EXPECT_EQ(warnings_for(room(poking, false), lucent::Precision::Float), 0);
  // walls of radius 1e6: the ceiling's centre, stored in float, moves it 0.025 up (its spacing
  // there is 1/16), and the lamp's cut part from 0.27 to 0.295: 9.5% bright in double as well
  // (image-mean z 38), which double's own note says
  Scene wide = room(poking, true);
  for (lucent::Sphere& sp : wide.spheres)
    if (sp.radius == 1e5) {
      for (int k = 0; k < 3; ++k)
        if (std::abs(sp.center[k]) > 5e4) sp.center[k] += (sp.center[k] > 0 ? 9e5 : -9e5);
      sp.radius = 1e6;
    }
  EXPECT_EQ(warnings_for(wide, lucent::Precision::Double), 1);
  EXPECT_EQ(warnings_for(wide, lucent::Precision::Float), 1);
}

// A point light close to a surface against the rounding there: 0.01 above the floor, the scene
// moved 1e4 along the floor's normal, the light's height was stored as 0.00977 (-2.3%; +5% of
// irradiance under it) and the render was wrong pixel by pixel in both precisions (65% of the
// pixels passed against the reference; the image mean within its noise), without a word (the
// precision review). Said now; not at the origin, nor for the light 4 above the floor.
TEST(Session, PointLightCloseToASurfaceAgainstTheRoundingWarns) {
  const std::string what = "a point light lies";
  auto near_floor = [](double shift) {
    Scene s = lucent::test::map_positions(lucent::test::scene_from(kScene), [&](glm::dvec3 p) {
      return p + glm::dvec3(0, shift, 0);
    });
    s.spheres[0].center.y += shift;
    s.lights[0].position = glm::dvec3(0.5, shift + 0.01, 2);
    return s;
  };
  EXPECT_EQ(warnings_containing(near_floor(1e4), lucent::Precision::Float, what), 1);
  EXPECT_EQ(warnings_containing(near_floor(1e4), lucent::Precision::Double, what), 1);
  EXPECT_EQ(warnings_containing(near_floor(0), lucent::Precision::Float, what), 0);
  EXPECT_EQ(warnings_containing(near_floor(0), lucent::Precision::Double, what), 0);
  EXPECT_EQ(warnings_containing(lucent::test::scene_from(kScene), lucent::Precision::Float, what),
            0);
}

// An area light within its own size of a surface whose float offsets are large against it:
// BSDF-sampled rays leave from the offset origin and see the lamp's edges shifted, so the share of
// its light MIS gives them is biased (a square lamp of side 0.006 at 0.003 over a floor of +-60
// rendered 0.12% bright, a sphere lamp of radius 0.0078 whose centre is 0.01 above it 0.18%:
// the light-sampling reviewer, forty-fourth session), without a word. Said now in float; not in
// double, nor for a lamp farther than its size (radius 0.003 at 0.01, whose error measured
// within noise), nor for a square lamp of side 0.1 at 0.003 (offsets 1/1700 of its size). The
// session's reviewer: a small object beside the lamp hid the floor (only the nearest surface
// counted), a lamp facing away from the floor and a sphere inside a lamp warned, and a sliver
// of a lamp through the floor did not (its vertices and centroid were all far from it).
TEST(Session, AreaLightWithinItsSizeOfACoarseSurfaceWarns) {
  const std::string what = "in float precision, ";
  const std::string tail = "a surface whose rays leave offset by up to";
  auto scene = [](const std::string& shapes) {
    return lucent::test::scene_from(R"({
      "camera": {"position": [0, 1, 3], "look_at": [0, 0, 0], "fov": 40},
      "film": {"width": 8, "height": 8},
      "integrator": {"type": "path", "spp": 1},
      "materials": {"g": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
                    "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [5, 5, 5]}},
      "shapes": [{"type": "triangles", "material": "g",
                  "positions": [[-60, 0, -60], [60, 0, -60], [60, 0, 60], [-60, 0, 60]],
                  "indices": [0, 2, 1, 0, 3, 2]}, )" +
                                    shapes + "]}");
  };
  auto n = [](double x) {
    char b[32];
    std::snprintf(b, sizeof b, "%.17g", x);
    return std::string(b);
  };
  // a square lamp facing down (or up), centred above the floor's origin
  auto square = [&](double side, double height, bool up = false) {
    const std::string a = n(side / 2), h = n(height);
    return R"({"type": "triangles", "material": "lamp", "positions": [[-)" + a + ", " + h + ", -" +
           a + "], [" + a + ", " + h + ", -" + a + "], [" + a + ", " + h + ", " + a + "], [-" + a +
           ", " + h + ", " + a +
           "]], \"indices\": " + (up ? "[0, 2, 1, 0, 3, 2]}" : "[0, 1, 2, 0, 2, 3]}");
  };
  auto sphere = [&](const std::string& material, double radius, glm::dvec3 c) {
    return R"({"type": "sphere", "material": ")" + material + R"(", "center": [)" + n(c.x) + ", " +
           n(c.y) + ", " + n(c.z) + "], \"radius\": " + n(radius) + "}";
  };
  auto warnings = [&](const std::string& shapes, lucent::Precision p = lucent::Precision::Float) {
    Renderer r = full_kernel_session(p);
    lucent::test::CaptureWarnings w;
    r.set_scene(scene(shapes));
    int count = 0;
    for (const std::string& line : w.all())
      count += line.find(what) != std::string::npos && line.find(tail) != std::string::npos;
    return count;
  };
  using lucent::Precision;
  EXPECT_EQ(warnings(square(0.006, 0.003)), 1);
  EXPECT_EQ(warnings(square(0.006, 0.003), Precision::Double), 0);
  EXPECT_EQ(warnings(square(0.006, 0.003, true)), 0);  // it lights the sky, not the floor
  // nor a coarse sphere under it (its plane's normal, not unit, made the sphere count)
  EXPECT_EQ(warnings(square(0.006, 0.003, true) + ", " + sphere("g", 60, {0, -60, 0})), 0);
  EXPECT_EQ(warnings(sphere("lamp", 0.0078, {0, 0.01, 0})), 1);
  // a small, precise sphere beside the lamp: the floor still counts
  EXPECT_EQ(
      warnings(sphere("lamp", 0.0078, {0, 0.01, 0}) + ", " + sphere("g", 0.001, {0.0093, 0.01, 0})),
      1);
  EXPECT_EQ(warnings(sphere("lamp", 0.003, {0, 0.01, 0})), 0);
  EXPECT_EQ(warnings(square(0.1, 0.003)), 0);
  EXPECT_EQ(warnings(square(0.006, 1.0)), 0);
  // a sphere inside a lamp far from the floor sees the lamp's dark inside only
  EXPECT_EQ(warnings(sphere("lamp", 0.01, {100, 5, 0}) + ", " + sphere("g", 0.001, {100, 5, 0})),
            0);
  // a sliver of a lamp through the floor: its ends far from it, its middle in it
  EXPECT_EQ(warnings(R"({"type": "triangles", "material": "lamp",
                         "positions": [[-1e-6, -0.01, 0], [1e-6, -0.01, 0], [0, 0.01, 0]],
                         "indices": [0, 1, 2]})"),
            1);
}

// Caustics reach a pixel through its filter only: with a near-delta filter (radius 1e-3) they
// vanished from an image that looked complete, without a word (the film review). Not said for
// a radius of 0.5, nor without a surface that makes caustics (the light paths are dropped).
TEST(Session, CausticsWithATinyFilterWarn) {
  const std::string what = "integrator.caustics with a filter radius of";
  Scene s = lucent::test::scene_from(kScene);
  s.integrator.caustics = true;
  s.film.filter.radius = 1e-3;
  EXPECT_EQ(warnings_containing(s, lucent::Precision::Float, what), 0);  // nothing makes caustics
  s.materials[0].type = lucent::MaterialType::Dielectric;
  s.materials[0].specular = glm::dvec3(1.0);
  EXPECT_EQ(warnings_containing(s, lucent::Precision::Float, what), 1);
  s.film.filter.radius = 0.5;
  EXPECT_EQ(warnings_containing(s, lucent::Precision::Float, what), 0);
}

// A material colour above 1 reflects more light than it receives: a diffuse albedo of 2 rendered
// a white furnace 1.73, without a word (diffuse_mirror refuses such values; the others warn),
// and so does an albedo texture's texel (a PFM of 2s rendered 2.12). Once per session (a render
// with 3 AOVs said it 4 times); not for colours of 1, not for plastic's specular colour (a
// Fresnel term's factor: its surface stays below 1), not for the AOV integrators.
TEST(Session, MaterialsThatGainEnergyWarn) {
  Renderer r = full_kernel_session();
  Scene s = lucent::test::scene_from(kScene);
  const std::string tail =
      " is above 1: the surface reflects more light than it receives (each bounce gains energy, "
      "and Russian roulette does not end such paths)";
  s.materials[0].albedo = glm::dvec3(0.7, 2.0, 0.5);
  {
    lucent::test::CaptureWarnings warnings;
    r.set_scene(s);
    r.set_scene(s);  // the same once
    EXPECT_EQ(warnings.count("material '" + s.materials[0].name + "': albedo 2 in green" + tail), 1)
        << warnings.dump();
    EXPECT_EQ(warnings.all().size(), 1u) << warnings.dump();
  }
  auto warnings_for = [&](const Scene& scene) {
    Renderer fresh = full_kernel_session();
    lucent::test::CaptureWarnings warnings;
    fresh.set_scene(scene);
    return warnings.all();
  };
  Scene aov = s;
  aov.integrator.type = lucent::IntegratorType::Albedo;
  EXPECT_TRUE(warnings_for(aov).empty());
  Scene plastic = lucent::test::scene_from(kScene);
  plastic.materials[0].type = lucent::MaterialType::Plastic;
  plastic.materials[0].specular = glm::dvec3(1.5);
  EXPECT_TRUE(warnings_for(plastic).empty());
  Scene one = lucent::test::scene_from(kScene);
  one.materials[0].albedo = glm::dvec3(1.0);
  EXPECT_TRUE(warnings_for(one).empty());
  Scene textured = one;
  lucent::Texture t;
  t.width = t.height = 2;
  t.rgba.assign(16, 0.5f);
  t.rgba[5] = 2.5f;  // pixel (1, 0), green
  textured.textures.push_back(t);
  textured.materials[0].albedo_texture = 0;
  const std::vector<std::string> w = warnings_for(textured);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("material '" + one.materials[0].name +
                      "': albedo texture's brightest texel 2.5" + tail),
            std::string::npos)
      << w[0];
}

// Radiance whose square overflows float (a point light of 1e22 W/sr, which the scene checks
// accept) is counted as non-finite, not summed: the pass's sum of squares became infinite, so
// were the variances, and a part file of it was refused by merge.
TEST(Session, SamplesWhoseSquareOverflowsAreCountedNotSummed) {
  Scene s = lucent::test::scene_from(kScene);
  s.lights[0].intensity = glm::dvec3(1e22);
  Renderer r = session();
  r.set_scene(s);
  r.render(4);
  const RenderResult res = r.result();
  EXPECT_GT(res.nonfinite, 0u);
  for (size_t i = 0; i < res.mean.rgb.size(); ++i) {
    ASSERT_TRUE(std::isfinite(res.mean.rgb[i])) << i;
    ASSERT_TRUE(std::isfinite(res.variance.rgb[i])) << i;
  }
  const lucent::Accumulation a = r.accumulation();
  for (size_t i = 0; i < a.sumsq.size(); ++i) ASSERT_TRUE(std::isfinite(a.sumsq[i])) << i;
}

// Two devices, and the pass of samples [0, 1) fails on one while the other's [1, 2) is kept: the
// accumulation is not one range from sample 0 any more. It once claimed [0, k) for the k samples
// the other device kept (a part file of it would have said so, and merged wrongly), and the next
// render started at first + done = k, rendering sample k twice. Now the accumulation is refused
// until reset(), and the next render starts after the last sample held.
TEST(Session, FailedPassOfOneDeviceLeavesNoFalseRange) {
  Scene s = lucent::test::scene_from(kScene);
  lucent::SessionOptions o = lucent::test::session_options();
  std::string one = std::to_string(lucent::select_device(o.device).index);
  o.device = one + "," + one;
  Renderer r(o);
  r.set_scene(s);
  {
    lucent::render_detail::ScopedPassFault fault(0);
    EXPECT_NE(error_of([&] { r.render(8); }).find("clEnqueueNDRangeKernel (injected by a test)"),
              std::string::npos);
  }
  // the other device's passes: [1, 1 + k), however many it finished before the failure stopped it
  const std::uint64_t k = r.spp();
  ASSERT_GE(k, 1u);
  EXPECT_NE(
      error_of([&] { r.accumulation(); })
          .find("accumulation: the session holds " + std::to_string(k) +
                " samples per pixel of [0, " + std::to_string(1 + k) + "), not one range from 0"),
      std::string::npos)
      << error_of([&] { r.accumulation(); });
  r.render(3);  // samples [1 + k, 4 + k): none twice
  EXPECT_NE(error_of([&] { r.accumulation(); })
                .find("holds " + std::to_string(k + 3) + " samples per pixel of [0, " +
                      std::to_string(4 + k) + "), not one range from 0"),
            std::string::npos)
      << error_of([&] { r.accumulation(); });
  EXPECT_EQ(r.spp(), k + 3);
  r.reset();
  r.render(2);
  EXPECT_EQ(r.accumulation().spp, 2u);
}

// A target call then a budget call: the result's planned relMSE is the last call's plan's, which
// a budget call has none of (it reported the target call's, stale); the calibration's gains stay,
// since the estimate still uses them.
TEST(Session, PlannedRelmseIsTheLastCallsPlan) {
  Renderer r = session();
  r.set_scene(lucent::test::scene_from(kScene));
  lucent::AdaptiveOptions ao;
  ao.target_error = 1e-2;
  ao.min_spp = 8;
  r.render_adaptive(ao);
  const RenderResult t = r.result();
  EXPECT_GT(t.planned_relmse, 0.0);
  EXPECT_GT(t.model_gain_a, 0.0);
  ao.target_error = 0;
  ao.budget_spp = 2.0 * double(t.spp) + 8;
  r.render_adaptive(ao);
  const RenderResult b = r.result();
  EXPECT_GT(b.spp, t.spp);
  EXPECT_EQ(b.target_error, 0.0);
  EXPECT_EQ(b.planned_relmse, 0.0);
  EXPECT_EQ(b.model_gain_a, t.model_gain_a);
}

// A call continues what an earlier call planned and did not render (here cancelled once its plan
// was made), but within its own max_spp: a call with max_spp 16 after one with 4096 rendered the
// earlier plan to its 4096 samples per pixel. Per half, a pixel ends at most at the larger of
// what it had and the cap's half.
TEST(Session, AdaptiveCallKeepsItsCapOverAnEarlierPlan) {
  Renderer r = session();
  r.set_scene(lucent::test::scene_from(kScene));
  lucent::AdaptiveOptions ao;
  ao.target_error = 1e-7;
  ao.min_spp = 8;
  ao.max_spp = 4096;
  const std::uint64_t pilot_spp = 3 * 4;  // halves A, B and C (every pixel of a small film)
  r.render_adaptive(ao, [&](const lucent::RenderProgress& p) {
    if (p.samples_target > pilot_spp) r.cancel();  // the plan is made
  });
  const RenderResult a = r.result();
  ASSERT_TRUE(a.cancelled);
  ASSERT_FALSE(a.pilot_incomplete);
  ASSERT_TRUE(a.plan_incomplete);
  ASSERT_GT(a.planned_spp, 1000u);
  ao.target_error = 1;
  ao.max_spp = 16;
  r.render_adaptive(ao);
  const RenderResult b = r.result();
  EXPECT_FALSE(b.cancelled);
  EXPECT_FALSE(b.plan_incomplete);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t i = 0; i < a.samples.size(); ++i)
    ASSERT_LE(b.samples[i], a.samples[i] + 16) << "pixel " << i;
}

// A pass's ray and non-finite counts are 64 bits: the kernel's 32-bit counters carry into a high
// word. They wrapped: a pass of more than 2^32 rays (a 16-megapixel film at several samples per
// pixel and deep paths) reported its rays modulo 2^32. Here each pass's counters start at
// 2^32 - 1 (ScopedCounterStart, which the session takes off again), so that the first ray or
// sample counted carries as the 2^32nd would: the counts equal those of the same samples counted
// from 0 (a wrap without the carry read as a count near 2^64).
TEST(Session, PassCountsCarryPast2To32) {
  Scene s = lucent::test::scene_from(kScene);
  s.lights[0].intensity = glm::dvec3(1e22);  // non-finite samples too (their squares overflow)
  Renderer r = session();
  r.set_scene(s);
  // passes of one sample each, the same passes every time: whether a sample counts as non-finite
  // depends on the pass's sum of squares before it
  auto render = [&r] {
    r.reset();
    for (int i = 0; i < 3; ++i) r.render(1);
    return r.result();
  };
  const RenderResult plain = render();
  ASSERT_GT(plain.rays, 0u);
  ASSERT_GT(plain.nonfinite, 0u);
  ASSERT_LT(plain.rays, 1u << 31);
  lucent::render_detail::ScopedCounterStart start(0xffffffffu);
  const RenderResult carried = render();
  EXPECT_EQ(carried.rays, plain.rays);
  EXPECT_EQ(carried.nonfinite, plain.nonfinite);
  EXPECT_EQ(r.accumulation().rays, plain.rays);
  EXPECT_EQ(r.accumulation().nonfinite, plain.nonfinite);
}

// Two devices and a time limit that is up once the first passes have run: an adaptive render
// dispatches round after round in one call, and each round after the limit still gave every
// device one pass (the pre-assignment of each device's first job did not look at the clock). With
// one-sample passes every round went to the pre-assigned jobs alone, so the render went on through
// its whole pilot and plan. Now the first round's two passes are all.
TEST(Session, SeveralDevicesStopAtTheTimeLimit) {
  lucent::SessionOptions o = lucent::test::session_options();
  std::string one = std::to_string(lucent::select_device(o.device).index);
  o.device = one + "," + one;
  Renderer r(o);
  ASSERT_EQ(r.devices().size(), 2u);
  r.set_scene(lucent::test::scene_from(kScene));
  lucent::AdaptiveOptions ao;
  ao.budget_spp = 32;
  ao.min_spp = 8;
  ao.max_seconds = 1e-6;  // up before any pass ends
  int calls = 0;
  lucent::RenderProgress p = r.render_adaptive(ao, [&](const lucent::RenderProgress&) { ++calls; });
  EXPECT_EQ(r.stats().passes, 2u) << "one pass per device, none after the time limit";
  EXPECT_EQ(calls, 2);
  EXPECT_GT(p.samples_done, 0u);
  EXPECT_LT(r.spp(), 8u) << "the pilot alone is 8 samples per pixel";
  EXPECT_FALSE(r.result().cancelled);
}

// A CancelScope (a convergence study's) makes a session's calls one operation for cancel(): a
// cancel asked for between two of them stops the next at once (each call's start cleared it, so
// the study went on), and once the scope ends a call's start drops such a cancel again, as the
// API says of a cancel while no render runs.
TEST(Session, CancelBetweenTheCallsOfAScopeStopsTheNext) {
  Renderer r = session();
  r.set_scene(lucent::test::scene_from(kScene));
  r.cancel();  // before the scope: not its operation's
  {
    lucent::render_detail::CancelScope scope(r, "a test");
    EXPECT_FALSE(scope.cancelled());
    r.render(1);
    EXPECT_FALSE(r.result().cancelled);
    r.cancel();
    EXPECT_TRUE(scope.cancelled());
    EXPECT_EQ(r.render(4).samples_done, 0u);
    EXPECT_TRUE(r.result().cancelled);
    EXPECT_EQ(r.spp(), 1u);
  }
  r.render(1);
  EXPECT_FALSE(r.result().cancelled);
  r.cancel();
  r.render(1);
  EXPECT_FALSE(r.result().cancelled) << "no render ran when it was asked for";
  EXPECT_EQ(r.spp(), 3u);
}

namespace {

/// An icosphere of 20,480 triangles under a point light: its triangles and their attributes
/// (1.25 MiB each) are arrays of 1 MiB or more, which live in host blocks (core/host_blocks.hpp).
Scene icosphere_scene() {
  const lucent::bvh::meshes::IndexedMesh ico = lucent::bvh::meshes::icosphere(5);
  lucent::SceneBuilder b;
  lucent::Film film;
  film.width = 16;
  film.height = 12;
  b.set_film(film);
  lucent::Material m;
  m.name = "m";
  m.type = lucent::MaterialType::Diffuse;
  b.add_material(m);
  lucent::MeshShape mesh;
  for (const auto& p : ico.positions) mesh.positions.emplace_back(p[0], p[1], p[2]);
  for (const auto& f : ico.faces)
    for (int k = 0; k < 3; ++k) mesh.indices.push_back(int(f[k]));
  mesh.material = "m";
  b.add_mesh(mesh);
  b.add_light(lucent::point_light({2, 3, 4}, {30, 30, 30}));
  return b.build();
}

/// Waits for the host blocks alive to come back to `n` (a buffer's block is released by its
/// destructor callback, which the driver may run late); returns how many are alive.
int blocks_back_to(int n) {
  for (int i = 0; i < 100 && lucent::render_detail::huge_page_blocks() != n; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  return lucent::render_detail::huge_page_blocks();
}

/// The host blocks that one packing of `s` holds.
int blocks_of_a_packing(const Scene& s) {
  const int before = lucent::render_detail::huge_page_blocks();
  const lucent::render_detail::PackedScene packed = lucent::render_detail::pack_scene(s);
  return lucent::render_detail::huge_page_blocks() - before;
}

}  // namespace

// A CPU device's scene buffers of 1 MiB or more are the packed arrays themselves: buffers made
// with CL_MEM_USE_HOST_PTR over the arrays' host blocks, not copies. They were copied into
// blocks of their own, so that a large mesh's packed scene was held twice (a 10^6-triangle soup:
// 346 MB twice). A buffer holds its block: the packing may be freed first, the buffer still
// reads it (AddressSanitizer would see a use after free), and the block goes with the buffer.
TEST(Session, CpuDeviceBuffersAreThePackedArrays) {
  lucent::cl_util::Context ctx{lucent::test::device()};
  if (!lucent::render_detail::buffers_in_host_memory(ctx.device.device))
    GTEST_SKIP() << "not a CPU device: " << ctx.device.info.name;
  const int before = lucent::render_detail::huge_page_blocks();
  auto packed = std::make_unique<lucent::render_detail::PackedScene>(
      lucent::render_detail::pack_scene(icosphere_scene()));
  ASSERT_GE(packed->triangles.size() * sizeof(lc_triangle),
            lucent::render_detail::kHugePageMinBuffer);
  ASSERT_GE(packed->tri_attrs.size() * sizeof(lc_triangle_attr),
            lucent::render_detail::kHugePageMinBuffer);
  const int held = lucent::render_detail::huge_page_blocks() - before;
  auto dev = std::make_unique<lucent::render_detail::DeviceScene>(ctx, *packed);
  EXPECT_EQ(dev->triangles.getInfo<CL_MEM_HOST_PTR>(),
            static_cast<void*>(packed->triangles.data()));
  EXPECT_EQ(dev->tri_attrs.getInfo<CL_MEM_HOST_PTR>(),
            static_cast<void*>(packed->tri_attrs.data()));
  EXPECT_EQ(lucent::render_detail::huge_page_blocks() - before, held) << "no block of their own";

  const std::vector<lc_triangle> triangles(packed->triangles.begin(), packed->triangles.end());
  packed.reset();
  EXPECT_EQ(lucent::render_detail::huge_page_blocks() - before, 2) << "the buffers hold theirs";
  std::vector<lc_triangle> read(triangles.size());
  ctx.queue.enqueueReadBuffer(dev->triangles, CL_TRUE, 0, read.size() * sizeof(lc_triangle),
                              read.data());
  EXPECT_EQ(std::memcmp(read.data(), triangles.data(), read.size() * sizeof(lc_triangle)), 0);
  dev.reset();
  ctx.queue.finish();
  EXPECT_EQ(blocks_back_to(before), before);
}

// set_scene on a CPU device: the arrays that did not change keep their storage (the buffers
// share it), those that changed get buffers over the new arrays. Materials, then the light,
// then the geometry (the triangles move, their attributes stay), an injected upload failure,
// and the first scene again: each renders, bit for bit, what a fresh session renders, and the
// session holds the host blocks of one packing, not of two (a kept buffer over the previous
// array while the session held the new, equal one). LUCENT_HUGE_PAGES=0 (no huge-page advice)
// renders the same.
TEST(Session, SetSceneSequencesOnSharedBuffersRenderAsAFreshSession) {
  const Scene first = icosphere_scene();
  Scene materials = first;
  materials.materials[0].albedo = glm::dvec3(0.8, 0.3, 0.2);
  Scene light = materials;
  light.lights[0].position = glm::dvec3(-2, 3, 4);
  Scene moved = light;
  for (glm::dvec3& p : moved.positions) p.x += 0.25;
  struct Step {
    const char* what;
    const Scene* scene;
    bool fault;
  };
  const Step steps[] = {{"first", &first, false}, {"materials", &materials, false},
                        {"light", &light, false}, {"moved", &moved, false},
                        {"fault", &first, true},  {"moved again", &moved, false}};
  const int before = lucent::render_detail::huge_page_blocks();
  const int one = blocks_of_a_packing(first);
  ASSERT_GE(one, 2) << "the triangles and their attributes at least";
  EXPECT_EQ(blocks_of_a_packing(moved), one);
  std::vector<RenderResult> fresh;
  for (const Step& st : steps) {
    Renderer f = session();
    f.set_scene(*st.scene);
    f.render(3);
    fresh.push_back(f.result());
  }
  EXPECT_FALSE(same_image(fresh[0], fresh[1])) << "the materials changed";
  EXPECT_FALSE(same_image(fresh[1], fresh[2])) << "the light moved";
  EXPECT_FALSE(same_image(fresh[2], fresh[3])) << "the mesh moved";
  ASSERT_EQ(blocks_back_to(before), before);
  {
    Renderer r = session();
    const bool cpu = r.devices().at(0).type == "CPU";
    for (size_t i = 0; i < std::size(steps); ++i) {
      const Step& st = steps[i];
      if (st.fault) {
        lucent::render_detail::ScopedUploadFault fault;
        Scene other = moved;
        other.materials[0].albedo = glm::dvec3(0.1, 0.9, 0.1);
        EXPECT_NE(error_of([&] { r.set_scene(other); }), "");
        EXPECT_NE(error_of([&] { r.render(1); }), "") << "the devices hold no scene";
      }
      r.set_scene(*st.scene);
      r.render(3);
      EXPECT_TRUE(same_image(r.result(), fresh[i])) << st.what;
      if (cpu) {
        EXPECT_EQ(blocks_back_to(before + one), before + one) << st.what;
      }
    }
  }
  EXPECT_EQ(blocks_back_to(before), before) << "freed with the session";

  lucent::test::ScopedEnv off("LUCENT_HUGE_PAGES", "0");
  Renderer r = session();
  r.set_scene(moved);
  r.render(3);
  EXPECT_TRUE(same_image(r.result(), fresh[3]));
}

// Two CPU devices in one session ("0,0": two contexts) make buffers over the same arrays, read
// only: the session holds one packing's blocks, and after set_scene both render the new scene
// (the samples of a one-device render, up to float summation order).
TEST(Session, TwoCpuDevicesShareThePackedArrays) {
  lucent::SessionOptions o = lucent::test::session_options();
  std::string one_device = std::to_string(lucent::select_device(o.device).index);
  o.device = one_device + "," + one_device;
  o.pass_seconds = 1e-4;  // many small passes, so that both devices take some
  const Scene first = icosphere_scene();
  Scene moved_scene = first;
  for (glm::dvec3& p : moved_scene.positions) p.y += 0.25;
  const Scene& moved = moved_scene;
  const int before = lucent::render_detail::huge_page_blocks();
  const int one = blocks_of_a_packing(first);
  {
    Renderer both(o);
    ASSERT_EQ(both.devices().size(), 2u);
    const bool cpu = both.devices().at(0).type == "CPU";
    for (const Scene* sc : {&first, &moved}) {
      both.set_scene(*sc);
      lucent::RenderProgress p = both.render(16);
      EXPECT_GT(p.devices[0].samples, 0u);
      EXPECT_GT(p.devices[1].samples, 0u);
      if (cpu) {
        EXPECT_EQ(blocks_back_to(before + one), before + one);
      }
      Renderer single = session();
      single.set_scene(*sc);
      single.render(16);
      expect_same_samples(both.result(), single.result());
    }
  }
  EXPECT_EQ(blocks_back_to(before), before);
}

// A process forked from one that had used OpenCL: its OpenCL calls hang for ever (the driver's
// threads do not survive a fork; a Python multiprocessing worker of the default start method did,
// in set_scene). Its first lucent call is an error saying so, in a session made before the fork
// and in one made after it.
TEST(Session, AForkOfAProcessThatUsedOpenClIsRefused) {
  auto before = std::make_unique<lucent::Renderer>(lucent::test::session_options());
  const lucent::Scene scene = lucent::test::scene_from(R"({"film": {"width": 4, "height": 4},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "sphere", "center": [0, 0, -3], "radius": 1, "material": "m"}]})");
  before->set_scene(scene);
  before->render(1);  // (its release hung in the child only after a render)
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::alarm(30);  // a hang ends the child (SIGALRM), not the test
    int refused = 0;
    auto refuses = [&](const std::function<void()>& call) {
      try {
        call();
      } catch (const lucent::Error& e) {
        refused += std::string(e.what()).rfind("this process is a fork of one that had used OpenCL",
                                               0) == 0;
      }
    };
    refuses([&] { before->set_scene(scene); });
    refuses([&] { before->render(1); });
    refuses([&] { lucent::Renderer after(lucent::test::session_options()); });
    refuses([&] { lucent::list_devices(); });
    // destroying the session made before the fork hung too (releasing its OpenCL objects)
    before.reset();
    ::_exit(refused);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 4);
}

namespace {
void own_stop_handler(int) {}
}  // namespace

// PoCL's LLVM installs its handlers for SIGINT, SIGTERM and SIGHUP over the process's own when
// PoCL initialises (SA_RESETHAND: two signals microseconds apart, GNU timeout's, found the
// default action in between and killed lucent with no word, 17 times in 30 during a kernel build;
// Python's SIGINT handler stayed behind LLVM's). The process's own stay in place across a session
// made, a kernel built and a render. (Checked in a process of its own: each ctest entry is one.)
TEST(Session, TheProcesssSignalHandlersStayItsOwn) {
  const int signals[] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction saved[3], own{};
  own.sa_handler = own_stop_handler;
  sigemptyset(&own.sa_mask);
  for (int i = 0; i < 3; ++i) ::sigaction(signals[i], &own, &saved[i]);
  {
    Renderer r(lucent::test::session_options());
    r.set_scene(lucent::test::scene_from(kScene));
    r.render(1);
    lucent::list_devices();
  }
  for (int i = 0; i < 3; ++i) {
    struct sigaction now {};
    ::sigaction(signals[i], &saved[i], &now);
    EXPECT_EQ(now.sa_handler, &own_stop_handler) << signals[i];
    EXPECT_EQ(now.sa_flags & (SA_RESETHAND | SA_NODEFER), 0) << signals[i];
  }
}

}  // namespace test_session
