// sphere lights (emissive spheres): a uniformly distributed point of the whole sphere.
#include "reference/light/light.hpp"

namespace lucent::ref {

namespace {

class SphereLight final : public AreaLight {
 public:
  using AreaLight::AreaLight;

 protected:
  void sample_point(double u1, double u2, dvec3& y, dvec3& ny) const override {
    const Sphere& sp = world_.scene.spheres[world_.prims[prim_].index];
    ny = uniform_sphere(u1, u2);
    y = sp.center + sp.radius * ny;
  }
};

}  // namespace

std::unique_ptr<Light> make_light_sphere(const World& world, int prim, double nlights) {
  return std::make_unique<SphereLight>(world, prim, nlights);
}

}  // namespace lucent::ref
