// Reference integrator: the scene's primitives in a plain median-split BVH. The shapes themselves
// are in geometry/<file>.cpp, one per entry of LC_SHAPE_TYPES, reached through shape_ops().
#include "reference/geometry/world.hpp"

#include <algorithm>
#include <string>

#include "lucent/error.hpp"

namespace lucent::ref {

#define LUCENT_REF_DECLARE_SHAPE(ID, Name, value, name, feature, file) \
  extern const ShapeOps shape_##file;
LC_SHAPE_TYPES(LUCENT_REF_DECLARE_SHAPE)
#undef LUCENT_REF_DECLARE_SHAPE

const ShapeOps& shape_ops(Shape shape) {
  switch (shape) {
#define LUCENT_REF_SHAPE_CASE(ID, Name, value, name, feature, file) \
  case Shape::Name:                                                 \
    return shape_##file;
    LC_SHAPE_TYPES(LUCENT_REF_SHAPE_CASE)
#undef LUCENT_REF_SHAPE_CASE
  }
  throw Error("reference: unknown shape type " + std::to_string(static_cast<int>(shape)));
}

void check_material(const Scene& scene, int material, const char* what, int i) {
  if (material < 0 || material >= static_cast<int>(scene.materials.size()))
    throw Error(scene.path + ": " + what + " " + std::to_string(i) + ": material index " +
                std::to_string(material) + " out of range");
}

namespace {

dvec3 centroid(const Box& b) { return 0.5 * (b.lo + b.hi); }

/// Slab test: does the ray meet the box within (0, tmax)?
bool hit_box(const Box& b, const Ray& r, const dvec3& inv, double tmax) {
  double t0 = 0, t1 = tmax;
  for (int a = 0; a < 3; ++a) {
    double ta = (b.lo[a] - r.o[a]) * inv[a];
    double tb = (b.hi[a] - r.o[a]) * inv[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

constexpr Shape kShapes[] = {
#define LUCENT_REF_SHAPE_LIST(ID, Name, ...) Shape::Name,
    LC_SHAPE_TYPES(LUCENT_REF_SHAPE_LIST)
#undef LUCENT_REF_SHAPE_LIST
};

}  // namespace

World::World(const Scene& s) : scene(s) {
  std::size_t first = 0;
  for (Shape shape : kShapes) {
    const ShapeOps& ops = shape_ops(shape);
    const std::size_t n = ops.count(s);
    shape_first_.push_back(first);
    first += n;
    for (std::size_t i = 0; i < n; ++i) {
      Box b;
      if (!ops.prepare(s, static_cast<int>(i), b)) {
        if (shape == Shape::Triangle) ++skipped_triangles;
        continue;
      }
      prims.push_back({shape, static_cast<int>(i), &ops});
      prim_boxes_.push_back(b);
    }
  }
  order_.resize(prims.size());
  for (size_t i = 0; i < prims.size(); ++i) order_[i] = static_cast<int>(i);
  if (!prims.empty()) build(0, static_cast<int>(prims.size()), 0);
}

std::size_t World::scene_index(int prim) const {
  const Prim& p = prims[prim];
  return shape_first_[static_cast<int>(p.shape)] + p.index;
}

int World::build(int first, int count, int depth) {
  BvhNode node;
  Box cbox;
  for (int i = first; i < first + count; ++i) {
    node.box.grow(prim_boxes_[order_[i]]);
    cbox.grow(centroid(prim_boxes_[order_[i]]));
  }
  int index = static_cast<int>(nodes_.size());
  nodes_.push_back(node);
  dvec3 ext = cbox.hi - cbox.lo;
  if (count <= 4 || depth > 60 || max3(ext) <= 0) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  int axis = ext.x > ext.y ? (ext.x > ext.z ? 0 : 2) : (ext.y > ext.z ? 1 : 2);
  int mid = first + count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + first + count,
                   [&](int a, int b) {
                     return centroid(prim_boxes_[a])[axis] < centroid(prim_boxes_[b])[axis];
                   });
  int left = build(first, mid - first, depth + 1);
  int right = build(mid, first + count - mid, depth + 1);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

bool World::intersect(const Ray& ray, double tmax, Hit& hit, int skip) const {
  if (nodes_.empty()) return false;
  dvec3 inv;
  for (int a = 0; a < 3; ++a) inv[a] = ray.d[a] != 0 ? 1.0 / ray.d[a] : 1e300;
  bool found = false;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& n = nodes_[stack[--top]];
    if (!hit_box(n.box, ray, inv, tmax)) continue;
    if (n.left < 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        const int prim = order_[i];
        if (prim == skip) continue;
        const Prim& p = prims[prim];
        if (p.ops->intersect(scene, p.index, ray, tmax, hit)) {
          hit.prim = prim;
          tmax = hit.t;
          found = true;
        }
      }
    } else {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return found;
}

bool World::occluded(const Ray& ray, double tmax, int skip) const {
  Hit h;
  return intersect(ray, tmax, h, skip);
}

Surface World::surface(const Ray& ray, const Hit& hit) const {
  Surface s;
  const Prim& p = prims[hit.prim];
  p.ops->surface(scene, p.index, ray, hit, s);
  s.prim = hit.prim;
  s.front = glm::dot(ray.d, s.ng) < 0;
  if (!s.front) {
    s.ng = -s.ng;
    s.ns = -s.ns;
  }
  // an interpolated normal facing away from the viewer (wo below the shading hemisphere, near a
  // silhouette of a coarse mesh): the geometric normal instead (docs/rendering-model.md)
  if (glm::dot(ray.d, s.ns) >= 0) s.ns = s.ng;
  return s;
}

}  // namespace lucent::ref
