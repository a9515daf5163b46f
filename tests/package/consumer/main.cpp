// A small tool built against the installed lucent: a render session renders a scene, moves the
// camera and renders again without rebuilding the BVH or the kernel (the session's counters say
// so), the one-shot lucent::render gives the same image, the same scene built in code gives the
// same image, and a wrong value is reported as the JSON loader would.
#include <cstdio>
#include <lucent/lucent.hpp>
#include <string>

// the umbrella header is every public header (compare, converge and reference were missing),
// and leaves no macro of its own making behind
#ifdef LUCENT_REGISTRY_ENUMERATOR
#error "lucent/scene.hpp left LUCENT_REGISTRY_ENUMERATOR defined"
#endif
// nor the kernel's helper macros of lucent/registry.h: only its type lists
#if defined(LC_ENABLED) || defined(LC_ENABLED_1) || defined(LC_ON_1) || defined(LC_PARAMS) || \
    defined(LC_OTHER_FEATURES) || defined(LC_SCENE_BUFFERS) || defined(LUCENT_REGISTRY_TYPES_ONLY)
#error "lucent's headers define the kernel's registry macros (LC_ENABLED, LC_PARAMS, ...)"
#endif
#ifndef LC_MATERIAL_TYPES
#error "lucent/scene.hpp does not give the registry's type lists"
#endif
static_assert(sizeof(lucent::CompareOptions) > 0 && sizeof(lucent::ConvergeOptions) > 0 &&
                  sizeof(lucent::ReferenceOptions) > 0,
              "lucent/lucent.hpp includes compare.hpp, converge.hpp and reference.hpp");

namespace {

int fail(const char* what) {
  std::fprintf(stderr, "consumer: %s\n", what);
  return 1;
}

}  // namespace

int main() {
  lucent::Scene scene = lucent::parse_scene(R"({
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 40},
    "film": {"width": 16, "height": 16},
    "integrator": {"type": "direct", "spp": 2},
    "materials": {"white": {"type": "diffuse", "albedo": [0.8, 0.8, 0.8]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}],
    "lights": [{"type": "point", "position": [0, 0, 4], "intensity": [10, 10, 10]}]
  })",
                                            "consumer.json");
  try {
    const lucent::SessionOptions env = lucent::SessionOptions::from_environment();
    lucent::Renderer renderer(env);
    renderer.set_scene(scene);
    renderer.render(2);
    lucent::RenderResult first = renderer.result();
    scene.camera.position.x += 0.5;
    renderer.set_scene(scene);
    renderer.render(2);
    lucent::RenderResult second = renderer.result();
    lucent::SessionStats s = renderer.stats();
    const float* c = first.mean.pixel(8, 8);
    std::printf(
        "lucent %s: centre pixel %g %g %g; after the camera move: %llu BVH build(s), %llu "
        "kernel build(s), %llu kernel reuse(s)\n",
        lucent::kVersion, c[0], c[1], c[2], static_cast<unsigned long long>(s.bvh_builds),
        static_cast<unsigned long long>(s.kernel_compiles + s.kernel_cache_loads),
        static_cast<unsigned long long>(s.kernel_reuses));
    if (!(c[0] > 0)) return fail("the centre pixel is black");
    if (second.spp != 2) return fail("the second render does not hold 2 spp");
    if (second.mean.rgb == first.mean.rgb) return fail("moving the camera changed nothing");
    if (s.bvh_builds != 1 || s.kernel_compiles + s.kernel_cache_loads != 1 || s.scene_packs != 2)
      return fail("the camera move rebuilt the BVH or the kernel");
    lucent::RenderOptions one_shot;  // the same device and kernels as the session's
    one_shot.device = env.device;
    one_shot.kernel_dir = env.kernel_dir;
    one_shot.cache_dir = env.cache_dir;
    if (lucent::render(scene, one_shot).mean.rgb != second.mean.rgb)
      return fail("the one-shot render differs from the session's");
    lucent::SceneBuilder b("consumer.json");
    lucent::Camera camera;
    camera.position = {0, 0, 4};
    camera.fov_degrees = 40;
    b.set_camera(camera);
    lucent::Film film;
    film.width = film.height = 16;
    b.set_film(film);
    lucent::Integrator integrator;
    integrator.type = lucent::parse_type<lucent::IntegratorType>("direct");
    integrator.spp = 2;
    b.set_integrator(integrator);
    lucent::Material white;
    white.name = "white";
    white.albedo = {0.8, 0.8, 0.8};
    b.add_material(white);
    b.add_sphere({{0, 0, 0}, 1, "white"});
    b.add_light(lucent::point_light({0, 0, 4}, {10, 10, 10}));
    lucent::RenderResult built = lucent::render(b.build(), one_shot);
    if (built.mean.rgb != first.mean.rgb)
      return fail("the scene built in code renders differently");

    std::string message;
    try {
      lucent::SceneBuilder bad("consumer.json");
      bad.add_sphere({{0, 0, 0}, 1, "white"});
    } catch (const lucent::Error& e) {
      message = e.what();
    }
    if (message != "consumer.json: /shapes/0/material: unknown material 'white'")
      return fail("the builder's error is not the loader's line");

    // the library's warnings reach a ScopedWarningSink (lucent/warnings.hpp), not stderr
    std::string warning;
    {
      lucent::ScopedWarningSink sink([&](const std::string& w) { warning = w; });
      lucent::parse_scene(R"({"camera": {"position": [0, 0, 4], "focus_distance": 3},
        "materials": {"w": {"type": "diffuse"}},
        "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "w"}]})",
                          "warned.json");
    }
    if (warning.find("warned.json: /camera/focus_distance: the aperture is 0") != 0)
      return fail("parse_scene's warning did not reach the ScopedWarningSink");
  } catch (const lucent::Error& e) {
    return fail(e.what());
  }
  return 0;
}
