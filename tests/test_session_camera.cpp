// Renderer::set_camera: a camera move without packing the scene again. It must render what a
// fresh session given the moved scene renders, bit for bit, pack and upload nothing but the light
// table an environment weighs by the camera, refuse a bad camera as set_scene does, and fall back
// to a whole set_scene where the kernel or the devices' buffers need one.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "lucent/scene_builder.hpp"
#include "lucent/session.hpp"
#include "render/device_scene.hpp"
#include "render/pack.hpp"
#include "render/resources.hpp"
#include "support.hpp"

namespace test_session_camera {

namespace {

using lucent::Camera;
using lucent::Renderer;
using lucent::RenderResult;
using lucent::Scene;
using lucent::SessionStats;
using lucent::test::error_of;

// a ground of 20 across under a sphere: the camera's distance to its look-at (5) bounds the
// region over which an environment's power is reckoned (pack_lights), so that moving the camera
// nearer changes the light table
const char* kScene = R"({
  "camera": {"position": [0, 1, 5], "look_at": [0, 0.5, 0], "fov": 40},
  "film": {"width": 16, "height": 12},
  "integrator": {"type": "path", "max_depth": 4, "spp": 4},
  "materials": {"w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]},
                "g": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
                "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [4, 4, 4]}},
  "shapes": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "w"},
             {"type": "sphere", "center": [1.5, 2, 0], "radius": 0.25, "material": "lamp"},
             {"type": "triangles", "material": "g",
              "positions": [[-10, 0, -10], [10, 0, -10], [10, 0, 10], [-10, 0, 10]],
              "indices": [0, 2, 1, 0, 3, 2]}],
  "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [20, 20, 20]}]})";

Scene base_scene() { return lucent::test::scene_from(kScene); }

/// The scene lit by an environment map as well (4 x 2 texels), whose selection probability
/// follows the camera's distance to its look-at.
Scene environment_scene() {
  Scene s = base_scene();
  lucent::Texture t;
  t.width = 4;
  t.height = 2;
  for (int i = 0; i < t.width * t.height; ++i)
    t.rgba.insert(t.rgba.end(), {0.2f + 0.1f * float(i), 0.3f, 0.4f, 1.0f});
  s.textures.push_back(t);
  s.lights.push_back(lucent::environment_map(static_cast<int>(s.textures.size()) - 1, 0.5));
  return s;
}

Renderer session() { return Renderer(lucent::test::session_options()); }

bool same_image(const RenderResult& a, const RenderResult& b) {
  return a.mean.rgb == b.mean.rgb && a.variance.rgb == b.variance.rgb && a.samples == b.samples &&
         a.spp == b.spp && a.rays == b.rays;
}

/// A fresh session's render of `s` at `spp`.
RenderResult fresh_render(const Scene& s, std::uint64_t spp, std::uint64_t* hash = nullptr) {
  Renderer r = session();
  r.set_scene(s);
  r.render(spp);
  if (hash) *hash = r.image_hash();
  return r.result();
}

Scene with_camera(Scene s, const Camera& c) {
  s.camera = c;
  return s;
}

// The move renders what a fresh session of the moved scene renders, bit for bit, and packs,
// builds and uploads nothing (the launch parameters go with every pass).
TEST(SessionCamera, MoveRendersTheMovedSceneAndPacksNothing) {
  const Scene s = base_scene();
  Renderer r = session();
  r.set_scene(s);
  r.render(2);
  const SessionStats before = r.stats();
  Camera c = s.camera;
  c.position = {1.5, 2, 4};
  c.roll_degrees = 10;
  r.set_camera(c);
  EXPECT_EQ(r.spp(), 0u) << "a new camera drops the accumulation";
  EXPECT_EQ(r.scene().camera.position, c.position);
  EXPECT_EQ(r.scene().camera.roll_degrees, 10);
  const SessionStats after = r.stats();
  EXPECT_EQ(after.camera_moves, before.camera_moves + 1);
  EXPECT_EQ(after.scene_packs, before.scene_packs) << "nothing packed";
  EXPECT_EQ(after.bvh_builds, before.bvh_builds);
  EXPECT_EQ(after.kernel_compiles + after.kernel_cache_loads,
            before.kernel_compiles + before.kernel_cache_loads);
  EXPECT_EQ(after.kernel_reuses, before.kernel_reuses) << "not a set_scene";
  EXPECT_EQ(after.buffer_uploads, before.buffer_uploads) << "no scene buffer written";
  EXPECT_EQ(after.bytes_uploaded, before.bytes_uploaded);
  r.render(3);
  std::uint64_t hash = 0;
  EXPECT_TRUE(same_image(r.result(), fresh_render(with_camera(s, c), 3, &hash)));
  EXPECT_EQ(r.image_hash(), hash);
  // the same camera again keeps the accumulation, as set_scene of an unchanged scene does
  r.set_camera(c);
  EXPECT_EQ(r.spp(), 3u);
  EXPECT_EQ(r.stats().camera_moves, before.camera_moves + 2);
}

// With an environment, the light table follows the camera's distance to its look-at: set_camera
// builds it again (an environment map's texel CDF too) and writes the lights and their CDF, the
// only buffers that change; a move at the same distance writes nothing.
TEST(SessionCamera, EnvironmentLightTableFollowsTheCamera) {
  const Scene s = environment_scene();
  Renderer r = session();
  r.set_scene(s);
  const SessionStats before = r.stats();
  Camera nearer = s.camera;
  nearer.position = {0, 1, 2};  // 2 from the look-at, not 5: less of the sky counts
  const lucent::render_detail::PackedScene a = lucent::render_detail::pack_scene(s);
  const lucent::render_detail::PackedScene b =
      lucent::render_detail::pack_scene(with_camera(s, nearer));
  ASSERT_NE(a.light_cdf, b.light_cdf) << "the test's premise: the light table changes";
  r.set_camera(nearer);
  const SessionStats moved = r.stats();
  EXPECT_EQ(moved.scene_packs, before.scene_packs);
  EXPECT_EQ(moved.camera_moves, before.camera_moves + 1);
  EXPECT_EQ(moved.buffer_uploads, before.buffer_uploads + 2) << "lights and light_cdf";
  EXPECT_EQ(moved.bytes_uploaded, before.bytes_uploaded + b.lights.size() * sizeof(lc_light) +
                                      b.light_cdf.size() * sizeof(float));
  r.render(3);
  std::uint64_t hash = 0;
  EXPECT_TRUE(same_image(r.result(), fresh_render(with_camera(s, nearer), 3, &hash)));
  EXPECT_EQ(r.image_hash(), hash);
  // around the look-at at the same distance: the table stays, nothing is written
  Camera around = nearer;
  around.position = {2, 1, 0};
  r.set_camera(around);
  EXPECT_EQ(r.stats().buffer_uploads, moved.buffer_uploads);
  r.render(2);
  EXPECT_TRUE(same_image(r.result(), fresh_render(with_camera(s, around), 2)));
}

// The same with a large environment map (512 x 512: its texels, 4 MiB, and its light table,
// 1 MiB, are host blocks that a CPU device's buffers share, core/host_blocks.hpp): a move that
// changes the table makes buffers over the new arrays, and the session holds one light table,
// not the previous one beside it (a kept buffer over the array the session replaced).
TEST(SessionCamera, LargeLightTableIsHeldOnce) {
  Scene s = base_scene();
  lucent::Texture t;
  t.width = t.height = 512;
  t.rgba.reserve(size_t(t.width) * t.height * 4);
  for (int i = 0; i < t.width * t.height; ++i)
    t.rgba.insert(t.rgba.end(), {0.2f + float(i % 7) * 0.1f, 0.3f, 0.2f + float(i % 5) * 0.1f, 1});
  s.textures.push_back(t);
  s.lights.push_back(lucent::environment_map(static_cast<int>(s.textures.size()) - 1, 0.5));
  Camera nearer = s.camera;
  nearer.position = {0, 1, 2};
  const lucent::render_detail::PackedScene a = lucent::render_detail::pack_scene(s);
  const lucent::render_detail::PackedScene b =
      lucent::render_detail::pack_scene(with_camera(s, nearer));
  ASSERT_GE(a.light_cdf.size() * sizeof(float), lucent::render_detail::kHugePageMinBuffer);
  ASSERT_NE(a.light_cdf, b.light_cdf) << "the test's premise: the light table changes";
  Camera around = nearer;
  around.position = {2, 1, 0};  // the same distance: the table stays

  const int before = lucent::render_detail::huge_page_blocks();
  Renderer r = session();
  r.set_scene(s);
  r.render(1);
  const bool cpu = r.devices().at(0).type == "CPU";
  const int held = lucent::render_detail::huge_page_blocks() - before;
  for (const Camera& c : {nearer, around, s.camera}) {
    r.set_camera(c);
    r.render(2);
    EXPECT_TRUE(same_image(r.result(), fresh_render(with_camera(s, c), 2)));
    // (a released buffer's block goes with its destructor callback, which may run late)
    for (int i = 0; i < 100 && lucent::render_detail::huge_page_blocks() - before != held; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (cpu) {
      EXPECT_EQ(lucent::render_detail::huge_page_blocks() - before, held);
    }
  }
}

// A bad camera is refused with set_scene's message, at the same place; the session keeps its
// camera and its accumulation, and renders on.
TEST(SessionCamera, BadCameraIsRefusedAsSetSceneRefusesIt) {
  Scene s = base_scene();
  s.path = "session.json";
  Renderer r = session();
  EXPECT_EQ(error_of([&] { r.set_camera(s.camera); }),
            "set_camera: the session has no scene (call set_scene first)");
  r.set_scene(s);
  r.render(2);
  const RenderResult before = r.result();
  const SessionStats stats = r.stats();
  auto refused = [&](const Camera& c, const std::string& expected) {
    const std::string by_scene = error_of([&] { session().set_scene(with_camera(s, c)); });
    const std::string by_camera = error_of([&] { r.set_camera(c); });
    EXPECT_EQ(by_camera, by_scene);
    EXPECT_NE(by_camera.find(expected), std::string::npos) << by_camera;
  };
  Camera c = s.camera;
  c.fov_degrees = 0;
  refused(c, "session.json: /camera/fov: must be in (0, 180) degrees, got 0");
  c = s.camera;
  c.up = c.look_at - c.position;
  refused(c, "session.json: /camera/up: must not be parallel to the viewing direction");
  c = s.camera;
  c.position.x = std::nan("");
  refused(c, "session.json: /camera/position/0:");
  c = s.camera;
  c.aperture = 1e6;  // (would change the kernel too: refused before that)
  refused(c, "session.json: /camera/aperture: must be at most 100 times the focus distance");
  EXPECT_EQ(r.scene().camera.position, s.camera.position);
  EXPECT_EQ(r.stats().camera_moves, stats.camera_moves);
  EXPECT_EQ(r.stats().scene_packs, stats.scene_packs);
  EXPECT_TRUE(same_image(r.result(), before)) << "the accumulation is kept";
  r.render(1);
  EXPECT_TRUE(same_image(r.result(), fresh_render(s, 3)));
}

// Its warnings are set_scene's, each once per session: a camera whose pixels are finer than
// float's steps warns at the first move there, neither at the next nor at a set_scene.
TEST(SessionCamera, WarningsAreGivenOncePerSession) {
  const Scene s = base_scene();
  Renderer r = session();
  r.set_scene(s);
  const std::string what = "float steps of the coordinates at the look-at distance";
  Camera fine = s.camera;
  fine.fov_degrees = 1e-4;
  auto warnings = [&](const std::function<void()>& f) {
    lucent::test::CaptureWarnings w;
    f();
    return w.count(what);
  };
  EXPECT_EQ(warnings([&] { r.set_camera(fine); }), 1);
  EXPECT_EQ(warnings([&] { r.set_camera(s.camera); }), 0);
  EXPECT_EQ(warnings([&] { r.set_camera(fine); }), 0);
  EXPECT_EQ(warnings([&] { r.set_scene(with_camera(s, fine)); }), 0);
  EXPECT_EQ(r.stats().scene_packs, 2u);
}

// A camera that changes the kernel (a lens where the pinhole kernel has none) and a session whose
// last set_scene failed (its devices hold no scene) take a whole set_scene of the held scene with
// the camera: counted as one, rendering what a fresh session renders.
TEST(SessionCamera, FallsBackToSetSceneWhereItMust) {
  const Scene s = base_scene();
  Renderer r = session();
  r.set_scene(s);
  r.render(2);
  Camera lens = s.camera;
  lens.aperture = 0.05;
  r.set_camera(lens);
  SessionStats st = r.stats();
  EXPECT_EQ(st.scene_packs, 2u) << "the kernel's build options changed: a set_scene";
  EXPECT_EQ(st.camera_moves, 0u);
  EXPECT_EQ(r.spp(), 0u);
  EXPECT_EQ(r.scene().camera.aperture, 0.05);
  EXPECT_EQ(r.scene().triangles.size(), s.triangles.size()) << "the scene moved back, whole";
  r.render(2);
  EXPECT_TRUE(same_image(r.result(), fresh_render(with_camera(s, lens), 2)));

  // a set_scene that fails part-way leaves the devices without a scene
  Scene other = s;
  other.materials[0].albedo = glm::dvec3(0.1, 0.9, 0.1);
  {
    lucent::render_detail::ScopedUploadFault fault;
    EXPECT_NE(error_of([&] { r.set_scene(other); }), "");
  }
  EXPECT_NE(error_of([&] { r.render(1); }).find("the last set_scene failed"), std::string::npos);
  Camera moved = lens;
  moved.position.x += 0.5;
  r.set_camera(moved);
  EXPECT_EQ(r.stats().scene_packs, 4u) << "the failed set_scene packed, and so did the fallback";
  r.render(2);
  EXPECT_TRUE(same_image(r.result(), fresh_render(with_camera(s, moved), 2)));
}

// Without specialisation the kernel holds the lens code whatever the camera: a lens is a move
// like any other.
TEST(SessionCamera, LensWithoutSpecialisationIsAMove) {
  const Scene s = base_scene();
  lucent::SessionOptions o = lucent::test::session_options();
  o.specialize = false;
  Renderer r(o);
  r.set_scene(s);
  Camera lens = s.camera;
  lens.aperture = 0.05;
  r.set_camera(lens);
  EXPECT_EQ(r.stats().scene_packs, 1u);
  EXPECT_EQ(r.stats().camera_moves, 1u);
  r.render(2);
  Renderer fresh(o);
  fresh.set_scene(with_camera(s, lens));
  fresh.render(2);
  EXPECT_TRUE(same_image(r.result(), fresh.result()));
}

// A move that fails while it writes the light table (an allocation failing, simulated) leaves
// the devices without a scene, as a failed set_scene does: rendering is refused until a call
// succeeds, and the next set_camera (a whole set_scene then) renders the moved scene.
TEST(SessionCamera, FailedLightUploadDropsTheDeviceScene) {
  const Scene s = environment_scene();
  Renderer r = session();
  r.set_scene(s);
  r.render(2);
  const RenderResult before = r.result();
  Camera nearer = s.camera;
  nearer.position = {0, 1, 2};
  {
    lucent::render_detail::ScopedUploadFault fault;
    const std::string msg = error_of([&] { r.set_camera(nearer); });
    EXPECT_NE(msg.find("clCreateBuffer (injected by a test)"), std::string::npos) << msg;
  }
  EXPECT_EQ(r.scene().camera.position, s.camera.position) << "the camera was not moved";
  EXPECT_NE(error_of([&] { r.render(1); }).find("the last set_scene failed"), std::string::npos);
  EXPECT_TRUE(same_image(r.result(), before));
  r.set_camera(nearer);
  r.render(2);
  EXPECT_TRUE(same_image(r.result(), fresh_render(with_camera(s, nearer), 2)));
}

// An adaptive render's accumulation is dropped by a move, as by set_scene: a uniform render
// follows without a reset.
TEST(SessionCamera, MoveDropsAnAdaptiveRender) {
  const Scene s = base_scene();
  Renderer r = session();
  r.set_scene(s);
  lucent::AdaptiveOptions ao;
  ao.budget_spp = 8;
  ao.min_spp = 4;
  r.render_adaptive(ao);
  Camera c = s.camera;
  c.position.x -= 1;
  r.set_camera(c);
  r.render(2);
  EXPECT_TRUE(same_image(r.result(), fresh_render(with_camera(s, c), 2)));
}

}  // namespace

}  // namespace test_session_camera
