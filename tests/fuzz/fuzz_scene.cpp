// Fuzz target: the whole scene loader (lucent::load_scene) on a bundle (fuzz_common.hpp) whose
// main file is the scene JSON, written as scene.json beside the bundle's other files, which the
// scene may name as meshes (and their MTL libraries and textures) and textures; then what a render
// or `lucent info` does with a loaded scene before it opens a device: validate_scene and the notes
// that follow loading, the packing (BVH, light table, device layout) with its notes, and the
// kernel features and build options the scene selects (a scene of at most kMaxPackedPrimitives
// primitives and kMaxPackedTexels texels: larger ones, which a 16 KB input reaches through
// textures, are loaded and validated only).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz_common.hpp"
#include "lucent/error.hpp"
#include "lucent/scene.hpp"
#include "render/features.hpp"
#include "render/pack.hpp"
#include "scene/validate.hpp"

namespace {

constexpr std::size_t kMaxPackedPrimitives = 1 << 14;
constexpr std::uint64_t kMaxPackedTexels = 1 << 18;

/// A loaded scene that a later step refuses is a finding: the loader let through what the
/// renderer cannot take (the message says what).
[[noreturn]] void refused_after_loading(const char* step, const lucent::Error& e) {
  std::fprintf(stderr, "fuzz invariant violated: %s refused a loaded scene: %s\n", step, e.what());
  std::abort();
}

void after_loading(const lucent::Scene& s) {
  using namespace lucent;
  try {
    scene_detail::validate_scene(s);  // Renderer::set_scene's, the reference renderer's
  } catch (const Error& e) {
    refused_after_loading("validate_scene", e);
  }
  (void)scene_detail::energy_gain_notes(s);
  (void)scene_detail::light_notes(s);
  (void)scene_detail::radiance_notes(s);
  std::uint64_t texels = 0;
  for (const Texture& t : s.textures) texels += std::uint64_t(t.width) * std::uint64_t(t.height);
  if (s.triangles.size() + s.spheres.size() > kMaxPackedPrimitives || texels > kMaxPackedTexels)
    return;
  render_detail::PackedScene packed;
  try {
    packed = render_detail::pack_scene(s);
  } catch (const Error& e) {
    refused_after_loading("pack_scene", e);
  }
  (void)render_detail::packing_notes(s, packed, true);
  (void)render_detail::packing_notes(s, packed, false);
  (void)render_detail::light_traced_caustics(s);
  (void)render_detail::build_options(s, packed, RenderOptions{});
  // the packing again over the first (Renderer::set_scene's reuse of the BVH)
  bool reused = false;
  try {
    (void)render_detail::pack_scene(s, &packed, &reused);
  } catch (const Error& e) {
    refused_after_loading("pack_scene (again)", e);
  }
  lucent::fuzz::check(reused, "a scene packed again did not reuse its own BVH");
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  lucent::fuzz::silence_warnings();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const lucent::fuzz::Bundle b = lucent::fuzz::parse_bundle(data, size);
  const std::string dir = lucent::fuzz::write_bundle(b, "scene.json");
  lucent::Scene s;
  try {
    s = lucent::load_scene(dir + "/scene.json");
  } catch (const lucent::Error&) {
    return 0;  // refused with a message: fine (any other exception escapes and is reported)
  }
  lucent::fuzz::check_scene(s);
  after_loading(s);
  return 0;
}
