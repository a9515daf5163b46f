// Reference integrator: triangles (Scene::triangles, one world-space list), in double precision.
// Degenerate (zero-area) and non-finite triangles are dropped, as the model says.
#include <algorithm>
#include <cmath>
#include <string>

#include "lucent/error.hpp"
#include "reference/geometry/world.hpp"

namespace lucent::ref {

namespace {

std::size_t count(const Scene& scene) { return scene.triangles.size(); }

bool prepare(const Scene& s, int i, Box& box) {
  const Triangle& t = s.triangles[i];
  check_material(s, t.material, "triangle", i);
  const int npos = static_cast<int>(s.positions.size());
  for (int k = 0; k < 3; ++k)
    if (t.v[k] < 0 || t.v[k] >= npos)
      throw Error(s.path + ": triangle " + std::to_string(i) + ": vertex index out of range");
  const dvec3 &a = s.positions[t.v[0]], &b = s.positions[t.v[1]], &c = s.positions[t.v[2]];
  double area2 = glm::length(glm::cross(b - a, c - a));
  if (!finite(a) || !finite(b) || !finite(c) || !(area2 > 0) || !std::isfinite(area2)) return false;
  box.grow(a);
  box.grow(b);
  box.grow(c);
  return true;
}

int material(const Scene& scene, int i) { return scene.triangles[i].material; }

double area(const Scene& s, int i) {
  const Triangle& t = s.triangles[i];
  return 0.5 * glm::length(glm::cross(s.positions[t.v[1]] - s.positions[t.v[0]],
                                      s.positions[t.v[2]] - s.positions[t.v[0]]));
}

// Moller-Trumbore
bool intersect(const Scene& scene, int i, const Ray& r, double tmax, Hit& hit) {
  const Triangle& tri = scene.triangles[i];
  const dvec3& v0 = scene.positions[tri.v[0]];
  dvec3 e1 = scene.positions[tri.v[1]] - v0, e2 = scene.positions[tri.v[2]] - v0;
  dvec3 pv = glm::cross(r.d, e2);
  double det = glm::dot(e1, pv);
  if (det == 0) return false;
  double inv = 1.0 / det;
  dvec3 tv = r.o - v0;
  double b1 = glm::dot(tv, pv) * inv;
  if (b1 < 0 || b1 > 1) return false;
  dvec3 qv = glm::cross(tv, e1);
  double b2 = glm::dot(r.d, qv) * inv;
  if (b2 < 0 || b1 + b2 > 1) return false;
  double t = glm::dot(e2, qv) * inv;
  if (!(t > 0 && t < tmax)) return false;
  hit.t = t;
  hit.b1 = b1;
  hit.b2 = b2;
  return true;
}

// Shading normal: the barycentric interpolation of the vertex normals, normalized, on the
// geometric normal's side; texture coordinates: the vertices' or the barycentrics (b1, b2).
void surface(const Scene& scene, int i, const Ray&, const Hit& hit, Surface& s) {
  const Triangle& t = scene.triangles[i];
  const dvec3 &v0 = scene.positions[t.v[0]], &v1 = scene.positions[t.v[1]],
              &v2 = scene.positions[t.v[2]];
  double b1 = hit.b1, b2 = hit.b2, b0 = 1 - b1 - b2;
  s.p = b0 * v0 + b1 * v1 + b2 * v2;
  s.ng = glm::normalize(glm::cross(v1 - v0, v2 - v0));
  s.ns = s.ng;
  if (t.n[0] >= 0 && t.n[1] >= 0 && t.n[2] >= 0) {
    // the three scaled by one power of two first when far from unit length (set directly:
    // Scene.normals), as the kernel's packing does: the square of a normal as short as 1e-160
    // underflowed (the geometric normal was used), and products with the barycentrics lost the
    // bits of subnormal ones (unit normals keep their bits)
    const double m = std::max({max_abs(scene.normals[t.n[0]]), max_abs(scene.normals[t.n[1]]),
                               max_abs(scene.normals[t.n[2]])});
    const int e = m > 0 && std::isfinite(m) && (m < 0x1p-32 || m > 0x1p32) ? -std::ilogb(m) : 0;
    auto scaled = [e](const dvec3& v) {
      return dvec3(std::ldexp(v.x, e), std::ldexp(v.y, e), std::ldexp(v.z, e));
    };
    const dvec3 n = b0 * scaled(scene.normals[t.n[0]]) + b1 * scaled(scene.normals[t.n[1]]) +
                    b2 * scaled(scene.normals[t.n[2]]);
    const double len = glm::length(n);
    if (len > 0) s.ns = glm::dot(n, s.ng) < 0 ? -n / len : n / len;
  }
  if (t.uv[0] >= 0 && t.uv[1] >= 0 && t.uv[2] >= 0)
    s.uv = b0 * scene.uvs[t.uv[0]] + b1 * scene.uvs[t.uv[1]] + b2 * scene.uvs[t.uv[2]];
  else
    s.uv = dvec2(b1, b2);
  s.material = t.material;
  // the offset of spawned rays: thousands of double ulps of the coordinates (1e-9 of them lost
  // contact shadows on large primitives: an offset of 1 on a floor of 1e9), relative only (an
  // absolute 1e-12 more was a tenth of a scene of size 1e-11, which rendered 11% too dark)
  s.err = kSpawnOffset * std::max(max_abs(v0), std::max(max_abs(v1), max_abs(v2)));
}

}  // namespace

extern const ShapeOps shape_triangle;
const ShapeOps shape_triangle = {"triangle", LightType::Triangle, count,  prepare, material,
                                 area,       intersect,           surface};

}  // namespace lucent::ref
