// point (position, intensity I in W/sr): irradiance I cos / r^2, a delta light.
#include "reference/light/light.hpp"

namespace lucent::ref {

namespace {

class PointLight final : public Light {
 public:
  PointLight(const lucent::Light& l, double nlights)
      : position_(l.position), intensity_(l.intensity), nlights_(nlights) {}

  bool is_delta() const override { return true; }

  LightSample sample(const dvec3& p, double, double) const override {
    LightSample ls;
    dvec3 to = position_ - p;
    ls.y = position_;
    ls.Le = intensity_;
    ls.dist2 = glm::dot(to, to);
    ls.dist = glm::length(to);
    ls.shadow_short = 1e-9;
    ls.delta = true;
    ls.pdf = 1 / nlights_;
    ls.valid = ls.dist > 0;
    if (ls.valid) ls.wi = to / ls.dist;
    return ls;
  }

  double pdf(const dvec3&, double, double) const override { return 0; }

  /// Light tracing: a uniform direction, beta = I / (p_select p_w) = I 4 pi size.
  LightEmission emit(double, double, double u3, double u4) const override {
    LightEmission e;
    e.y = position_;
    e.d = uniform_sphere(u3, u4);
    e.beta = intensity_ / ((1 / nlights_) * (1 / (4 * kPi)));
    e.valid = true;
    return e;
  }

 private:
  dvec3 position_, intensity_;
  double nlights_;
};

}  // namespace

std::unique_ptr<Light> make_light_point(const World& world, int index, double nlights) {
  return std::make_unique<PointLight>(world.scene.lights[index], nlights);
}

}  // namespace lucent::ref
