// A tiny program built against the installed lucent: parses a scene, renders it and checks that
// the image is not black.
#include <cstdio>

#include <lucent/lucent.hpp>

int main() {
  lucent::Scene scene = lucent::parse_scene(R"({
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 40},
    "film": {"width": 16, "height": 16},
    "integrator": {"type": "direct", "spp": 2},
    "materials": {"white": {"type": "diffuse", "albedo": [0.8, 0.8, 0.8]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}],
    "lights": [{"type": "point", "position": [0, 0, 4], "intensity": [10, 10, 10]}]
  })", "consumer.json");
  lucent::RenderResult r = lucent::render(scene);
  const float* c = r.mean.pixel(8, 8);
  std::printf("lucent %s: centre pixel %g %g %g\n", lucent::kVersion, c[0], c[1], c[2]);
  return c[0] > 0 ? 0 : 1;
}
