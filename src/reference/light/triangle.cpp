// triangle lights (emissive triangles): a uniformly distributed point of the triangle; they emit
// from their front side, (v1 - v0) x (v2 - v0).
#include <cmath>

#include "reference/light/light.hpp"

namespace lucent::ref {

namespace {

class TriangleLight final : public AreaLight {
 public:
  using AreaLight::AreaLight;

 protected:
  void sample_point(double u1, double u2, dvec3& y, dvec3& ny) const override {
    const Scene& s = world_.scene;
    const Triangle& t = s.triangles[world_.prims[prim_].index];
    const dvec3 &v0 = s.positions[t.v[0]], &v1 = s.positions[t.v[1]], &v2 = s.positions[t.v[2]];
    double su = std::sqrt(u1);
    double b0 = 1 - su, b1 = u2 * su;
    y = b0 * v0 + b1 * v1 + (1 - b0 - b1) * v2;
    ny = glm::normalize(glm::cross(v1 - v0, v2 - v0));
  }
};

}  // namespace

std::unique_ptr<Light> make_light_triangle(const World& world, int prim, double nlights) {
  return std::make_unique<TriangleLight>(world, prim, nlights);
}

}  // namespace lucent::ref
