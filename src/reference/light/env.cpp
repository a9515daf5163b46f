// environment (radiance): the constant radiance of every ray that escapes the scene.
#include "reference/light/light.hpp"

namespace lucent::ref {

namespace {

class ConstantEnvironment final : public EnvironmentLight {
 public:
  ConstantEnvironment(const lucent::Light& l, double nlights)
      : EnvironmentLight(nlights), radiance_(l.radiance) {}
  dvec3 radiance(const dvec3&) const override { return radiance_; }

 private:
  dvec3 radiance_;
};

}  // namespace

std::unique_ptr<Light> make_light_env(const World& world, int index, double nlights) {
  return std::make_unique<ConstantEnvironment>(world.scene.lights[index], nlights);
}

}  // namespace lucent::ref
