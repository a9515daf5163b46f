#pragma once
// The reference integrator's BSDFs: one class per material type of LC_MATERIAL_TYPES, in
// bsdf/<file>.cpp, behind the interface below. Each file defines
//   std::unique_ptr<Bsdf> make_bsdf_<file>(const Scene&, const Material&, const ShadingPoint&)
// and make_bsdf() dispatches on Material::type through the registry, so a new material type is
// its registry entry and its file. Every direction is in world space; cosines are taken with the
// shading normal n, which faces wo.
#include <memory>

#include "reference/common.hpp"

namespace lucent::ref {

/// The surface point a BSDF is built for.
struct ShadingPoint {
  dvec3 n{0, 0, 1};   ///< shading normal, on wo's side
  dvec3 ng{0, 0, 1};  ///< geometric normal, on wo's side
  dvec2 uv{0.0};
  bool front = true;  ///< wo is on the front side (outside of a sphere, front of a triangle)
};

/// A sampled BSDF direction.
struct BsdfSample {
  dvec3 wi{0.0};
  dvec3 weight{0.0};  ///< f |cos| / pdf (or the specular weight)
  double pdf = 0;     ///< solid-angle pdf; meaningless when delta
  /// Refraction (delta or rough): eta = n_transmitted / n_incident, whose 1 / eta^2 the weight
  /// holds (radiance transport); light tracing, which carries power, multiplies it back. 1
  /// otherwise.
  double eta = 1;
  bool delta = false;
  bool valid = false;
};

/// What the Whitted integrator sees of a BSDF (docs/rendering-model.md, "whitted"): a diffuse
/// part lit by point lights only, and at most one reflected and one transmitted ray, each with a
/// deterministic weight.
struct WhittedLobes {
  bool diffuse = false;  ///< adds albedo / pi * sum over point lights of I cos / r^2
  dvec3 albedo{0.0};
  bool reflect = false;  ///< traces reflect_dir, weighted by reflect_weight
  dvec3 reflect_dir{0.0}, reflect_weight{0.0};
  bool transmit = false;  ///< traces transmit_dir, weighted by transmit_weight
  dvec3 transmit_dir{0.0}, transmit_weight{0.0};
};

class Bsdf {
 public:
  explicit Bsdf(const ShadingPoint& sp) : n_(sp.n), ng_(sp.ng), front_(sp.front) {}
  virtual ~Bsdf() = default;

  /// Delta BSDFs scatter into isolated directions: eval and pdf are 0, only sample() reaches
  /// them, and the path integrator does no light sampling at them.
  virtual bool is_delta() const { return false; }
  /// f(wo, wi) |cos(wi, n)|; 0 for delta BSDFs and for directions the BSDF does not reach.
  virtual dvec3 eval(const dvec3& wo, const dvec3& wi) const = 0;
  /// Solid-angle density with which sample() returns a valid wi.
  virtual double pdf(const dvec3& wo, const dvec3& wi) const = 0;
  virtual BsdfSample sample(const dvec3& wo, double u_lobe, double u1, double u2) const = 0;
  /// The albedo AOV (docs/rendering-model.md, "albedo").
  virtual dvec3 albedo() const = 0;
  virtual WhittedLobes whitted(const dvec3& wo) const = 0;

 protected:
  dvec3 n_, ng_;
  bool front_;

  /// The sample of a non-delta BSDF in direction wi: weight eval / pdf; invalid where either is 0.
  BsdfSample sampled(const dvec3& wo, const dvec3& wi) const;
  /// Reflective BSDFs reach no wi below the geometric surface nor below the shading normal.
  bool below(const dvec3& wi) const { return glm::dot(wi, ng_) <= 0 || glm::dot(wi, n_) <= 0; }
  /// Mirror direction of wo about n.
  dvec3 reflect(const dvec3& wo) const;
  /// Whitted's mirror lobe: the reflection of wo about n with `weight`, where it leaves the
  /// geometric surface.
  WhittedLobes mirror_lobe(const dvec3& wo, const dvec3& weight) const;
};

/// The BSDF of material `m` at `sp` (textures looked up in scene.textures).
std::unique_ptr<Bsdf> make_bsdf(const Scene& scene, const Material& m, const ShadingPoint& sp);

/// The material's albedo at uv: its texture if it has one, else its colour.
dvec3 albedo_at(const Scene& scene, const Material& m, dvec2 uv);

#define LUCENT_REF_DECLARE_BSDF(ID, Name, value, name, feature, file, ...)      \
  std::unique_ptr<Bsdf> make_bsdf_##file(const Scene& scene, const Material& m, \
                                         const ShadingPoint& sp);
LC_MATERIAL_TYPES(LUCENT_REF_DECLARE_BSDF)
#undef LUCENT_REF_DECLARE_BSDF

}  // namespace lucent::ref
