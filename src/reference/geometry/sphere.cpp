// Reference integrator: spheres (Scene::spheres), in double precision.
#include <algorithm>
#include <cmath>

#include "reference/geometry/world.hpp"

namespace lucent::ref {

namespace {

std::size_t count(const Scene& scene) { return scene.spheres.size(); }

bool prepare(const Scene& scene, int i, Box& b) {
  const Sphere& sp = scene.spheres[i];
  check_material(scene, sp.material, "sphere", i);
  if (!(sp.radius > 0) || !finite(sp.center) || !std::isfinite(sp.radius)) return false;
  b.grow(sp.center - dvec3(sp.radius));
  b.grow(sp.center + dvec3(sp.radius));
  return true;
}

int material(const Scene& scene, int i) { return scene.spheres[i].material; }

double area(const Scene& scene, int i) {
  double r = scene.spheres[i].radius;
  return 4 * kPi * r * r;
}

bool intersect(const Scene& scene, int i, const Ray& r, double tmax, Hit& hit) {
  const Sphere& s = scene.spheres[i];
  dvec3 f = r.o - s.center;
  double b = glm::dot(f, r.d);
  dvec3 l = f - b * r.d;  // offset of the centre from the ray line: no cancellation
  double disc = s.radius * s.radius - glm::dot(l, l);
  if (disc < 0) return false;
  double c = glm::dot(f, f) - s.radius * s.radius;
  double q = -b - std::copysign(std::sqrt(disc), b);
  if (q == 0) return false;
  double t0 = c / q, t1 = q;
  if (t0 > t1) std::swap(t0, t1);
  double t = t0 > 0 ? t0 : t1;
  if (!(t > 0 && t < tmax)) return false;
  hit.t = t;
  return true;
}

void surface(const Scene& scene, int i, const Ray& ray, const Hit& hit, Surface& s) {
  const Sphere& sp = scene.spheres[i];
  dvec3 n = glm::normalize(ray.o + hit.t * ray.d - sp.center);
  s.p = sp.center + sp.radius * n;
  s.ng = s.ns = n;
  // u eastward seen from outside, the image's centre at +z (docs/rendering-model.md)
  s.uv = dvec2(0.5 + std::atan2(n.x, n.z) / (2 * kPi),
               0.5 + std::asin(std::clamp(n.y, -1.0, 1.0)) / kPi);
  s.material = sp.material;
  s.err = kSpawnOffset * (max_abs(sp.center) + sp.radius);  // as a triangle's (triangle.cpp)
}

}  // namespace

extern const ShapeOps shape_sphere;
const ShapeOps shape_sphere = {"sphere", LightType::Sphere, count,  prepare, material,
                               area,     intersect,         surface};

}  // namespace lucent::ref
