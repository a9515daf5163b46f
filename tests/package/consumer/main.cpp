// A tiny program built against the installed lucent: renders a scene parsed from JSON and the
// same scene built in code, checks that both images are equal and not black, and that a wrong
// value is reported as the JSON loader would.
#include <cstdio>
#include <lucent/lucent.hpp>
#include <string>

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
  lucent::RenderResult r = lucent::render(scene);
  const float* c = r.mean.pixel(8, 8);
  std::printf("lucent %s: centre pixel %g %g %g\n", lucent::kVersion, c[0], c[1], c[2]);

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
  lucent::RenderResult built = lucent::render(b.build());
  bool same = built.mean.rgb == r.mean.rgb;

  std::string message;
  try {
    lucent::SceneBuilder bad("consumer.json");
    bad.add_sphere({{0, 0, 0}, 1, "white"});
  } catch (const lucent::Error& e) {
    message = e.what();
  }
  bool named = message == "consumer.json: /shapes/0/material: unknown material 'white'";
  std::printf("built in code: %s; error: %s\n", same ? "same image" : "DIFFERENT image",
              message.c_str());
  return c[0] > 0 && same && named ? 0 : 1;
}
