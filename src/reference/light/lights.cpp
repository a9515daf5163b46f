// The reference's light list and light-type dispatch (generated from LC_LIGHT_TYPES), and the
// sampling shared by the environments (uniform directions) and by area lights (uniform points;
// light tracing: a uniform point and a cosine direction about its front normal).
#include <string>

#include "lucent/error.hpp"
#include "reference/light/light.hpp"

namespace lucent::ref {

namespace {

std::unique_ptr<Light> make_light(LightType type, const World& world, int index, double nlights) {
  switch (type) {
#define LUCENT_REF_LIGHT_CASE(ID, Name, value, name, feature, file, ...) \
  case LightType::Name:                                                  \
    return make_light_##file(world, index, nlights);
    LC_LIGHT_TYPES(LUCENT_REF_LIGHT_CASE)
#undef LUCENT_REF_LIGHT_CASE
  }
  throw Error(world.scene.path + ": light " + std::to_string(index) + ": unknown type " +
              std::to_string(static_cast<int>(type)));
}

}  // namespace

Lights::Lights(const World& world) : prim_light_(world.prims.size(), -1) {
  const Scene& scene = world.scene;
  struct Entry {
    LightType type;
    int index;
  };
  std::vector<Entry> entries;
  for (size_t i = 0; i < scene.lights.size(); ++i)
    entries.push_back({scene.lights[i].type, static_cast<int>(i)});
  for (size_t i = 0; i < world.prims.size(); ++i) {
    const int prim = static_cast<int>(i);
    if (!scene.materials[world.material(prim)].emissive()) continue;
    prim_light_[prim] = static_cast<int>(entries.size());
    entries.push_back({world.ops(prim).light, prim});
  }
  const double n = static_cast<double>(entries.size());
  for (const Entry& e : entries) {
    lights_.push_back(make_light(e.type, world, e.index, n));
    if (lights_.back()->is_environment()) env_ = lights_.back().get();
  }
}

LightSample Lights::sample(const dvec3& p, double u_select, double u1, double u2) const {
  if (lights_.empty()) return LightSample{};
  const double n = static_cast<double>(lights_.size());
  int i = static_cast<int>(std::min(lights_.size() - 1, static_cast<size_t>(u_select * n)));
  LightSample ls = lights_[i]->sample(p, u1, u2);
  ls.light = i;
  return ls;
}

LightEmission Lights::emit(double u_select, double u1, double u2, double u3, double u4) const {
  if (lights_.empty()) return LightEmission{};
  const double n = static_cast<double>(lights_.size());
  int i = static_cast<int>(std::min(lights_.size() - 1, static_cast<size_t>(u_select * n)));
  return lights_[i]->emit(u1, u2, u3, u4);
}

// ------------------------------------------------------------------------------------------
// environments: a uniform direction on the sphere

LightSample EnvironmentLight::sample(const dvec3&, double u1, double u2) const {
  LightSample ls;
  ls.wi = uniform_sphere(u1, u2);
  ls.pdf = pdf(ls.wi, kInf, 0);
  ls.Le = radiance(ls.wi);
  ls.valid = true;
  return ls;
}

double EnvironmentLight::pdf(const dvec3&, double, double) const {
  return 1 / (4 * kPi * nlights_);
}

// ------------------------------------------------------------------------------------------
// area lights: a uniform point of the primitive's area

AreaLight::AreaLight(const World& world, int prim, double nlights)
    : world_(world),
      prim_(prim),
      nlights_(nlights),
      area_(world.ops(prim).area(world.scene, world.prims[prim].index)),
      emission_(world.scene.materials[world.material(prim)].emission) {}

LightSample AreaLight::sample(const dvec3& p, double u1, double u2) const {
  LightSample ls;
  sample_point(u1, u2, ls.y, ls.ny);
  ls.skip = prim_;
  // The light's own primitive cannot hide a point of it that faces p (a sphere is convex), so it
  // is left out of the shadow test: near its silhouette, the ray from the offset origin would
  // otherwise graze it just before the sampled point.
  ls.shadow_short = 1e-7;
  ls.Le = emission_;
  dvec3 to = ls.y - p;
  ls.dist = glm::length(to);
  if (ls.dist <= 0) return ls;
  ls.wi = to / ls.dist;
  double cos_l = -glm::dot(ls.ny, ls.wi);  // > 0: the point's front side faces p
  if (cos_l <= 0) return ls;
  ls.pdf = pdf(ls.wi, ls.dist, cos_l);
  ls.valid = true;
  return ls;
}

LightEmission AreaLight::emit(double u1, double u2, double u3, double u4) const {
  LightEmission e;
  dvec3 ny;
  sample_point(u1, u2, e.y, ny);
  e.d = cosine_direction(ny, u3, u4);
  const double cos0 = glm::dot(e.d, ny);
  if (!(cos0 > 0)) return e;
  // Le cos0 / (p_select p_A p_w) with p_select = 1 / n, p_A = 1 / area, p_w = cos0 / pi
  e.beta = emission_ * cos0 / ((1 / nlights_) * (1 / area_) * (cos0 / kPi));
  e.skip = prim_;  // the emitted ray leaves the primitive's front side: a sphere is convex
  e.valid = true;
  return e;
}

double AreaLight::pdf(const dvec3&, double dist, double cos_l) const {
  if (cos_l <= 0) return 0;
  return dist * dist / (cos_l * area_ * nlights_);
}

}  // namespace lucent::ref
