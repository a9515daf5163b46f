#pragma once
// The reference's own geometry: its primitives (one file per shape type of LC_SHAPE_TYPES,
// geometry/<file>.cpp), a plain median-split BVH over them, and the surface at a hit.
#include <cstddef>
#include <vector>

#include "reference/common.hpp"

namespace lucent::ref {

/// The shape types, from the registry: Shape::Sphere, Shape::Triangle, ...
#define LUCENT_REF_SHAPE_ENUMERATOR(ID, Name, value, ...) Name = value,
enum class Shape { LC_SHAPE_TYPES(LUCENT_REF_SHAPE_ENUMERATOR) };
#undef LUCENT_REF_SHAPE_ENUMERATOR

struct Hit {
  double t = kInf;
  int prim = -1;          ///< index into World::prims
  double b1 = 0, b2 = 0;  ///< barycentrics of v1, v2 (triangles)
};

/// The surface at a hit, oriented towards the incoming ray.
/// Rays spawned from a surface leave it this fraction of its primitive's largest coordinate
/// (Surface::err: thousands of double ulps, which Moller-Trumbore's error on thin triangles
/// needs); render_reference warns when that reaches 1/16 of the scene's small features.
constexpr double kSpawnOffset = 1e-12;

struct Surface {
  dvec3 p;   ///< position
  dvec3 ng;  ///< geometric normal on the incoming side
  dvec3 ns;  ///< shading normal, on the same side as ng
  dvec2 uv;
  double err = 0;  ///< offset distance that leaves the surface safely
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

/// One shape type, implemented by geometry/<file>.cpp as `const ShapeOps shape_<file>`. Element
/// i is the i-th of the scene's list of that shape (Scene::spheres, Scene::triangles).
struct ShapeOps {
  const char* what;  ///< names an element in messages ("sphere 3: ...")
  LightType light;   ///< the area light type of its emissive elements
  std::size_t (*count)(const Scene& scene);
  /// Checks element i's references (throws lucent::Error naming the scene and the element);
  /// false when it is degenerate or not finite (dropped, as the model says), else its bounds.
  bool (*prepare)(const Scene& scene, int i, Box& bounds);
  int (*material)(const Scene& scene, int i);
  double (*area)(const Scene& scene, int i);
  /// Nearest intersection with t in (0, tmax): sets hit.t (and the barycentrics).
  bool (*intersect)(const Scene& scene, int i, const Ray& ray, double tmax, Hit& hit);
  /// The surface at a hit: p, err, uv, material, and ng, ns on the element's front side.
  void (*surface)(const Scene& scene, int i, const Ray& ray, const Hit& hit, Surface& s);
};

const ShapeOps& shape_ops(Shape shape);

/// Throws lucent::Error when `material` is no index into scene.materials.
void check_material(const Scene& scene, int material, const char* what, int i);

/// A primitive of the reference's own acceleration structure.
struct Prim {
  Shape shape = Shape::Sphere;
  int index = 0;                  ///< into the scene's list of that shape
  const ShapeOps* ops = nullptr;  ///< shape_ops(shape)
};

struct BvhNode {
  Box box;
  int left = -1, right = -1;  ///< children, -1 in leaves
  int first = 0, count = 0;   ///< leaf range in World::order_
};

/// Scene geometry in the reference's own form.
class World {
 public:
  explicit World(const Scene& scene);

  const Scene& scene;
  std::vector<Prim> prims;
  /// Triangles dropped as degenerate (zero area in double) or non-finite.
  std::size_t skipped_triangles = 0;

  /// Closest hit with t in (0, tmax), ignoring primitive `skip` (if >= 0).
  bool intersect(const Ray& ray, double tmax, Hit& hit, int skip = -1) const;
  /// Any hit with t in (0, tmax), ignoring primitive `skip` (if >= 0).
  bool occluded(const Ray& ray, double tmax, int skip = -1) const;
  Surface surface(const Ray& ray, const Hit& hit) const;

  const ShapeOps& ops(int prim) const { return *prims[prim].ops; }
  int material(int prim) const { return ops(prim).material(scene, prims[prim].index); }
  /// Index of the primitive in scene order: the spheres, then the triangles (registry order).
  std::size_t scene_index(int prim) const;

 private:
  std::vector<BvhNode> nodes_;
  std::vector<int> order_;
  std::vector<Box> prim_boxes_;
  std::vector<std::size_t> shape_first_;  ///< per shape type: scene index of its element 0
  int build(int first, int count, int depth);
};

}  // namespace lucent::ref
