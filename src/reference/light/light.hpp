#pragma once
// The reference integrator's lights: one class per light type of LC_LIGHT_TYPES, in
// light/<file>.cpp, each file defining
//   std::unique_ptr<Light> make_light_<file>(const World&, int index, double nlights)
// (index: into Scene::lights for the scene's lights, into World::prims for the area lights that
// emissive shapes make). Next-event estimation chooses among all of them uniformly, and samples
// each by its own strategy, deliberately not the kernel's: area lights by a uniform point of their
// whole area, environments by a uniform direction on the sphere.
#include <memory>
#include <vector>

#include "reference/common.hpp"
#include "reference/geometry/world.hpp"

namespace lucent::ref {

/// A light and a direction towards it, drawn by Light::sample.
struct LightSample {
  int light = -1;           ///< index into the light list
  dvec3 wi{0.0};            ///< unit direction from the shading point
  dvec3 y{0.0}, ny{0.0};    ///< the light's point (and its front normal, area lights)
  dvec3 Le{0.0};            ///< radiance arriving along wi; delta lights: the intensity (W/sr)
  double dist = kInf;       ///< distance to y (kInf: at infinity, the environment)
  double dist2 = 0;         ///< delta lights: squared distance, for the inverse-square falloff
  double pdf = 0;           ///< solid-angle pdf times the selection probability (1 / size);
                            ///< delta lights: the selection probability alone
  double shadow_short = 0;  ///< shadow rays stop this fraction of their length short of y
  int skip = -1;            ///< primitive the shadow ray ignores: the area light's own
  bool delta = false;       ///< a point light
  bool valid = false;       ///< false when the sampled point does not face the shading point
};

/// Light leaving a light, drawn by Light::emit (light tracing, integrator.caustics).
struct LightEmission {
  dvec3 y{0.0};     ///< the point y0 the light leaves from
  dvec3 d{0.0};     ///< unit direction of the emitted ray
  dvec3 beta{0.0};  ///< Le |cos| / (p_select p_A p_w); point lights I / (p_select p_w)
  int skip = -1;    ///< primitive the emitted ray ignores: the area light's own
  bool valid = false;
};

class Light {
 public:
  virtual ~Light() = default;
  virtual bool is_delta() const { return false; }
  /// Lights at infinity: radiance() is the radiance of the rays that escape the scene.
  virtual bool is_environment() const { return false; }
  /// A direction from p towards the light. Occlusion is not tested.
  virtual LightSample sample(const dvec3& p, double u1, double u2) const = 0;
  /// The pdf (solid angle, times the selection probability) with which sample() returns
  /// direction wi towards a point at distance dist whose front normal makes cosine cos_l with
  /// -wi: what multiple importance sampling weighs BSDF-sampled rays with. 0 for delta lights.
  virtual double pdf(const dvec3& wi, double dist, double cos_l) const = 0;
  /// Environments: radiance arriving from direction -d (escaping along d); others: 0.
  virtual dvec3 radiance(const dvec3&) const { return dvec3(0.0); }
  /// A point and a direction of light leaving the light (docs/rendering-model.md, "Caustics by
  /// light tracing"), from two pairs of numbers; beta includes the selection probability (1 /
  /// size). Environments are no light-tracing source: invalid.
  virtual LightEmission emit(double, double, double, double) const { return LightEmission{}; }
};

/// Environments, sampled uniformly over the sphere whatever their radiance; env.cpp and
/// env_map.cpp give the radiance.
class EnvironmentLight : public Light {
 public:
  explicit EnvironmentLight(double nlights) : nlights_(nlights) {}
  bool is_environment() const override { return true; }
  LightSample sample(const dvec3& p, double u1, double u2) const override;
  double pdf(const dvec3& wi, double dist, double cos_l) const override;

 private:
  double nlights_;
};

/// Emissive primitives, sampled by a uniformly distributed point of their area (a whole sphere's
/// surface: the half that faces away gives invalid samples); sphere.cpp and triangle.cpp give the
/// point.
class AreaLight : public Light {
 public:
  AreaLight(const World& world, int prim, double nlights);
  LightSample sample(const dvec3& p, double u1, double u2) const override;
  double pdf(const dvec3& wi, double dist, double cos_l) const override;
  /// A uniform point of the area (sample_point) and a cosine-distributed direction about its
  /// front normal: beta = Le cos / (1 / size * 1 / area * cos / pi) = Le pi area size.
  LightEmission emit(double u1, double u2, double u3, double u4) const override;

 protected:
  const World& world_;
  int prim_;
  /// A uniformly distributed point y of the primitive, with its front normal ny.
  virtual void sample_point(double u1, double u2, dvec3& y, dvec3& ny) const = 0;

 private:
  double nlights_, area_;
  dvec3 emission_;
};

/// Next-event estimation's lights: the scene's lights in Scene::lights order, then one area light
/// per emissive primitive in World::prims order. Each is chosen with probability 1 / size.
class Lights {
 public:
  explicit Lights(const World& world);
  std::size_t size() const { return lights_.size(); }
  bool empty() const { return lights_.empty(); }
  const Light& operator[](std::size_t i) const { return *lights_[i]; }

  /// Chooses a light uniformly with u_select, then a direction from p towards it.
  LightSample sample(const dvec3& p, double u_select, double u1, double u2) const;
  /// Light tracing: chooses a light uniformly with u_select, then light leaving it (beta
  /// includes the selection probability 1 / size).
  LightEmission emit(double u_select, double u1, double u2, double u3, double u4) const;
  /// The environment, or null.
  const Light* environment() const { return env_; }
  /// The area light of primitive `prim`, or null.
  const Light* area_light(int prim) const {
    return prim_light_[prim] < 0 ? nullptr : lights_[prim_light_[prim]].get();
  }
  /// MIS pdf of a BSDF-sampled ray that hits primitive `prim` at distance dist, cosine cos_l to
  /// its front normal: 0 when prim is no light.
  double pdf_hit(int prim, const dvec3& wi, double dist, double cos_l) const {
    const Light* l = area_light(prim);
    return l ? l->pdf(wi, dist, cos_l) : 0;
  }

 private:
  std::vector<std::unique_ptr<Light>> lights_;
  std::vector<int> prim_light_;  ///< per World::prims: index into lights_ or -1
  const Light* env_ = nullptr;
};

#define LUCENT_REF_DECLARE_LIGHT(ID, Name, value, name, feature, file, ...) \
  std::unique_ptr<Light> make_light_##file(const World& world, int index, double nlights);
LC_LIGHT_TYPES(LUCENT_REF_DECLARE_LIGHT)
#undef LUCENT_REF_DECLARE_LIGHT

}  // namespace lucent::ref
