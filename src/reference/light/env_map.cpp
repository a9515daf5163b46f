// environment map (file, scale): an equirectangular image, looked up by nearest texel
// (docs/rendering-model.md), times scale. Sampled uniformly like the constant environment.
#include "reference/light/light.hpp"
#include "reference/texture.hpp"

namespace lucent::ref {

namespace {

class EnvironmentMap final : public EnvironmentLight {
 public:
  EnvironmentMap(const Scene& scene, const lucent::Light& l, double nlights)
      : EnvironmentLight(nlights), scale_(l.radiance) {
    if (l.texture >= 0 && l.texture < static_cast<int>(scene.textures.size()))
      texture_ = &scene.textures[l.texture];
  }
  dvec3 radiance(const dvec3& d) const override {
    if (!texture_) return dvec3(0.0);
    return scale_ * equirect_rgb(*texture_, d);
  }

 private:
  dvec3 scale_;
  const Texture* texture_ = nullptr;
};

}  // namespace

std::unique_ptr<Light> make_light_env_map(const World& world, int index, double nlights) {
  return std::make_unique<EnvironmentMap>(world.scene, world.scene.lights[index], nlights);
}

}  // namespace lucent::ref
