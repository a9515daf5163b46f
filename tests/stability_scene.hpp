// The small scenes of the stability and precision tests (tests/test_stability_scene.cpp,
// tests/test_precision.cpp), and moving their positions.
#pragma once

#include <cmath>
#include <cstdio>
#include <functional>
#include <glm/glm.hpp>
#include <string>

#include "lucent/scene.hpp"

namespace lucent::test {

// A floor quad, two diffuse spheres, a standing triangle, a closed box mesh (12 triangles,
// rotated), a point light and an emissive sphere (out of view), path integrator; objects 0.3-6 in
// size around the origin.
inline std::string stability_scene_json() {
  // box: 0.5 x 0.5 x 0.5 standing on the floor at (0, 0, 1.25), rotated 30 degrees about y
  std::string pos;
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  for (int i = 0; i < 8; ++i) {
    double x = (i & 1) ? 0.25 : -0.25, y = (i & 2) ? 0.5 : 0.0, z = (i & 4) ? 0.25 : -0.25;
    char buf[128];
    std::snprintf(buf, sizeof buf, "%s[%.17g, %.17g, %.17g]", i ? ", " : "", c * x + s * z, y,
                  -s * x + c * z + 1.25);
    pos += buf;
  }
  return R"({
    "camera": {"position": [0, 1.2, 5], "look_at": [0, 0.4, 0], "fov": 38},
    "film": {"width": 24, "height": 24},
    "integrator": {"type": "path", "max_depth": 4},
    "materials": {"floor": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
                  "red": {"type": "diffuse", "albedo": [0.8, 0.25, 0.2]},
                  "blue": {"type": "diffuse", "albedo": [0.2, 0.3, 0.8]},
                  "green": {"type": "diffuse", "albedo": [0.3, 0.7, 0.3]},
                  "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [6, 5, 4]}},
    "shapes": [{"type": "triangles", "material": "floor",
                "positions": [[-3,0,-3],[3,0,-3],[3,0,3],[-3,0,3]], "indices": [0,2,1, 0,3,2]},
               {"type": "sphere", "center": [-0.8, 0.6, 0], "radius": 0.6, "material": "red"},
               {"type": "sphere", "center": [0.9, 0.5, 0.4], "radius": 0.5, "material": "blue"},
               {"type": "triangles", "material": "blue",
                "positions": [[-2,0,-1.5],[2,0,-1.5],[0,2,-1.8]], "indices": [0,1,2]},
               {"type": "triangles", "material": "green", "positions": [)" +
         pos + R"(],
                "indices": [0,2,3, 0,3,1, 4,5,7, 4,7,6, 0,1,5, 0,5,4, 2,6,7, 2,7,3,
                            0,4,6, 0,6,2, 1,3,7, 1,7,5]},
               {"type": "sphere", "center": [1.2, 2.2, 1.0], "radius": 0.3, "material": "lamp"}],
    "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [30, 28, 25]}]
  })";
}

// A diffuse plane (z = t, 10 x 10) lit only by an emissive sphere (radius 0.5) centred at
// t + (lamp_x, lamp_y, 2), seen from above by a 16 x 16 camera; every coordinate offset by t.
inline std::string sphere_light_over_plane_json(double t, double lamp_x, double lamp_y) {
  char buf[2048];
  std::snprintf(buf, sizeof buf, R"({
      "camera": {"position": [%.17g, %.17g, %.17g], "look_at": [%.17g, %.17g, %.17g],
                 "up": [0, 0, 1], "fov": 40},
      "film": {"width": 16, "height": 16},
      "integrator": {"type": "path", "max_depth": 2},
      "materials": {"plane": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
                    "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [4, 4, 4]}},
      "shapes": [{"type": "triangles", "material": "plane",
                  "positions": [[%.17g,%.17g,%.17g],[%.17g,%.17g,%.17g],[%.17g,%.17g,%.17g],
                                [%.17g,%.17g,%.17g]], "indices": [0,1,2, 0,2,3]},
                 {"type": "sphere", "center": [%.17g, %.17g, %.17g], "radius": 0.5,
                  "material": "lamp"}]})",
                t, t - 3, t + 1, t, t, t, t - 5, t - 5, t, t + 5, t - 5, t, t + 5, t + 5, t, t - 5,
                t + 5, t, t + lamp_x, t + lamp_y, t + 2);
  return buf;
}

// Every position p -> f(p): camera position and look_at, vertices, sphere centres, lights.
inline Scene map_positions(Scene scene, const std::function<glm::dvec3(glm::dvec3)>& f) {
  scene.camera.position = f(scene.camera.position);
  scene.camera.look_at = f(scene.camera.look_at);
  for (auto& p : scene.positions) p = f(p);
  for (auto& sp : scene.spheres) sp.center = f(sp.center);
  for (auto& l : scene.lights) l.position = f(l.position);
  return scene;
}

}  // namespace lucent::test
