#pragma once
// Internals of the reference integrator (src/reference/): double precision everywhere, plain
// structs, no sharing with the kernel's geometry, BSDF or light code.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "lucent/scene.hpp"

namespace lucent::ref {

using glm::dvec2;
using glm::dvec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = 1e300;

struct Ray {
  dvec3 o;
  dvec3 d;  ///< unit length
};

/// A primitive of the reference's own acceleration structure.
struct Prim {
  bool sphere = false;
  int index = 0;  ///< into Scene::spheres or Scene::triangles
};

struct Hit {
  double t = kInf;
  int prim = -1;  ///< index into World::prims
  double b1 = 0, b2 = 0;  ///< barycentrics of v1, v2 (triangles)
};

/// The surface at a hit, oriented towards the incoming ray.
struct Surface {
  dvec3 p;        ///< position
  dvec3 ng;       ///< geometric normal on the incoming side
  dvec3 ns;       ///< shading normal, on the same side as ng
  dvec2 uv;
  double err = 0; ///< offset distance that leaves the surface safely
  int material = 0;
  int prim = -1;
  bool front = true;  ///< the ray hit the front side (outside of a sphere, front of a triangle)
};

struct Box {
  dvec3 lo{kInf, kInf, kInf};
  dvec3 hi{-kInf, -kInf, -kInf};
  void grow(const dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
};

struct BvhNode {
  Box box;
  int left = -1, right = -1;  ///< children, -1 in leaves
  int first = 0, count = 0;   ///< leaf range in World::order
};

/// An area light: one emissive sphere or triangle.
struct AreaLight {
  int prim = 0;  ///< index into World::prims
  double area = 0;
};

/// Scene geometry and light list, in the reference's own form.
class World {
 public:
  explicit World(const Scene& scene);

  const Scene& scene;
  std::vector<Prim> prims;
  std::vector<AreaLight> area_lights;
  std::vector<int> prim_light;  ///< per prim: index into area_lights or -1
  dvec3 bounds_lo{0.0}, bounds_hi{0.0};

  /// Closest hit with t in (0, tmax), ignoring primitive `skip` (if >= 0).
  bool intersect(const Ray& ray, double tmax, Hit& hit, int skip = -1) const;
  /// Any hit with t in (0, tmax), ignoring primitive `skip` (if >= 0).
  bool occluded(const Ray& ray, double tmax, int skip = -1) const;
  Surface surface(const Ray& ray, const Hit& hit) const;

  /// Uniformly distributed point on primitive `prim`, with its outward (front) normal.
  void sample_area(int prim, double u1, double u2, dvec3& p, dvec3& n) const;

 private:
  std::vector<BvhNode> nodes_;
  std::vector<int> order_;
  std::vector<Box> prim_boxes_;
  int build(int first, int count, int depth);
  bool hit_prim(int prim, const Ray& ray, double tmax, Hit& hit) const;
};

/// One light of next-event estimation's list.
struct LightRef {
  enum Kind { Point, Env, Area } kind;
  int index;  ///< Scene::lights for Point and Env, World::area_lights for Area
};

/// Next-event estimation's lights, each chosen with probability 1 / size: point lights and the
/// environment in Scene::lights order, then the area lights. `env` receives the Scene::lights
/// index of the environment, or -1.
std::vector<LightRef> light_list(const World& world, int& env);

/// A light and a direction towards it, drawn by sample_light.
struct LightSample {
  int light = -1;          ///< index into the light list
  dvec3 wi{0.0};           ///< unit direction from the shading point
  dvec3 y{0.0}, ny{0.0};   ///< area lights: the sampled point and its front normal
  double dist = kInf;      ///< distance to the light's point (kInf for the environment)
  double pdf = 0;          ///< solid-angle pdf times the selection probability (1 / size)
  bool delta = false;      ///< point light: pdf is the selection probability alone
  bool valid = false;      ///< false when the sampled point does not face the shading point
};

/// Chooses a light uniformly with u_select, then a direction from p: the environment uniformly
/// over the sphere, area lights by a uniform point of their area (a whole sphere's surface; the
/// half that faces away gives an invalid sample). Occlusion is not tested.
LightSample sample_light(const World& world, const std::vector<LightRef>& lights, const dvec3& p,
                         double u_select, double u1, double u2);

/// Solid-angle pdf with which sample_light returns a direction towards the environment.
inline double env_light_pdf(size_t nlights) { return 1 / (4 * kPi * nlights); }

/// Selection probability times area density of the area light on prim, as a solid-angle pdf
/// seen from a point at distance `dist` whose direction makes cosine `cos_l` with the light's
/// front normal; 0 when prim is no light or cos_l <= 0.
double area_light_pdf(const World& world, size_t nlights, int prim, double dist, double cos_l);

/// Bilinear, repeating lookup of a texture's RGB; uv (0, 0) is the bottom-left corner.
dvec3 texture_rgb(const Texture& tex, dvec2 uv);

/// A sampled BSDF direction.
struct BsdfSample {
  dvec3 wi;
  dvec3 weight{0.0};  ///< f cos / pdf (or the specular weight)
  double pdf = 0;     ///< solid-angle pdf; meaningless when delta
  bool delta = false;
  bool valid = false;
};

/// The material at a surface point, ready for evaluation and sampling.
struct Bsdf {
  const Material* m = nullptr;
  dvec3 albedo{0.0};  ///< texture applied
  dvec3 n, ng;        ///< shading and geometric normals, on wo's side
  bool front = true;

  bool is_delta() const;
  /// f(wo, wi) |cos(wi, n)|, 0 for delta materials and for invalid directions.
  dvec3 eval(const dvec3& wo, const dvec3& wi) const;
  /// Solid-angle density with which sample() returns wi.
  double pdf(const dvec3& wo, const dvec3& wi) const;
  BsdfSample sample(const dvec3& wo, double u_lobe, double u1, double u2) const;
};

Bsdf make_bsdf(const Scene& scene, const Surface& s);

/// Luminance-free helpers.
inline double max3(const dvec3& v) { return glm::max(v.x, glm::max(v.y, v.z)); }

}  // namespace lucent::ref
