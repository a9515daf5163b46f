// Reference integrator: its own geometry. Spheres and triangles in double precision, a plain
// median-split BVH, area sampling of emitters, texture lookup.
#include <algorithm>
#include <cmath>
#include <string>

#include "lucent/error.hpp"
#include "reference/reference_internal.hpp"

namespace lucent::ref {

namespace {

bool finite(const dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

double max_abs(const dvec3& v) { return std::max(std::abs(v.x), std::max(std::abs(v.y), std::abs(v.z))); }

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

}  // namespace

World::World(const Scene& s) : scene(s) {
  const int nmat = static_cast<int>(s.materials.size());
  auto check_material = [&](int m, const std::string& what) {
    if (m < 0 || m >= nmat)
      throw Error(s.path + ": " + what + ": material index " + std::to_string(m) + " out of range");
  };
  for (size_t i = 0; i < s.spheres.size(); ++i) {
    const Sphere& sp = s.spheres[i];
    check_material(sp.material, "sphere " + std::to_string(i));
    if (!(sp.radius > 0) || !finite(sp.center) || !std::isfinite(sp.radius)) continue;
    prims.push_back({true, static_cast<int>(i)});
    Box b;
    b.grow(sp.center - dvec3(sp.radius));
    b.grow(sp.center + dvec3(sp.radius));
    prim_boxes_.push_back(b);
  }
  const int npos = static_cast<int>(s.positions.size());
  for (size_t i = 0; i < s.triangles.size(); ++i) {
    const Triangle& t = s.triangles[i];
    check_material(t.material, "triangle " + std::to_string(i));
    for (int k = 0; k < 3; ++k)
      if (t.v[k] < 0 || t.v[k] >= npos)
        throw Error(s.path + ": triangle " + std::to_string(i) + ": vertex index out of range");
    const dvec3 &a = s.positions[t.v[0]], &b = s.positions[t.v[1]], &c = s.positions[t.v[2]];
    double area2 = glm::length(glm::cross(b - a, c - a));
    if (!finite(a) || !finite(b) || !finite(c) || !(area2 > 0) || !std::isfinite(area2))
      continue;  // degenerate or non-finite: dropped, as the model says
    prims.push_back({false, static_cast<int>(i)});
    Box box;
    box.grow(a);
    box.grow(b);
    box.grow(c);
    prim_boxes_.push_back(box);
  }
  prim_light.assign(prims.size(), -1);
  for (size_t i = 0; i < prims.size(); ++i) {
    const Prim& p = prims[i];
    int mat = p.sphere ? s.spheres[p.index].material : s.triangles[p.index].material;
    if (!s.materials[mat].emissive()) continue;
    double area;
    if (p.sphere) {
      double r = s.spheres[p.index].radius;
      area = 4 * kPi * r * r;
    } else {
      const Triangle& t = s.triangles[p.index];
      area = 0.5 * glm::length(glm::cross(s.positions[t.v[1]] - s.positions[t.v[0]],
                                          s.positions[t.v[2]] - s.positions[t.v[0]]));
    }
    prim_light[i] = static_cast<int>(area_lights.size());
    area_lights.push_back({static_cast<int>(i), area});
  }
  Box all;
  for (const Box& b : prim_boxes_) all.grow(b);
  if (!prims.empty()) {
    bounds_lo = all.lo;
    bounds_hi = all.hi;
  }
  order_.resize(prims.size());
  for (size_t i = 0; i < prims.size(); ++i) order_[i] = static_cast<int>(i);
  if (!prims.empty()) build(0, static_cast<int>(prims.size()), 0);
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

bool World::hit_prim(int prim, const Ray& r, double tmax, Hit& hit) const {
  const Prim& p = prims[prim];
  if (p.sphere) {
    const Sphere& s = scene.spheres[p.index];
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
    hit.prim = prim;
    return true;
  }
  // Moller-Trumbore
  const Triangle& tri = scene.triangles[p.index];
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
  hit.prim = prim;
  hit.b1 = b1;
  hit.b2 = b2;
  return true;
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
      for (int i = n.first; i < n.first + n.count; ++i)
        if (order_[i] != skip && hit_prim(order_[i], ray, tmax, hit)) {
          tmax = hit.t;
          found = true;
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
  s.prim = hit.prim;
  if (p.sphere) {
    const Sphere& sp = scene.spheres[p.index];
    dvec3 n = glm::normalize(ray.o + hit.t * ray.d - sp.center);
    s.p = sp.center + sp.radius * n;
    s.ng = s.ns = n;
    s.uv = dvec2(0.5 + std::atan2(n.z, n.x) / (2 * kPi),
                 0.5 + std::asin(std::clamp(n.y, -1.0, 1.0)) / kPi);
    s.material = sp.material;
    s.err = 1e-9 * (max_abs(sp.center) + sp.radius) + 1e-12;
  } else {
    const Triangle& t = scene.triangles[p.index];
    const dvec3 &v0 = scene.positions[t.v[0]], &v1 = scene.positions[t.v[1]],
                &v2 = scene.positions[t.v[2]];
    double b1 = hit.b1, b2 = hit.b2, b0 = 1 - b1 - b2;
    s.p = b0 * v0 + b1 * v1 + b2 * v2;
    s.ng = glm::normalize(glm::cross(v1 - v0, v2 - v0));
    s.ns = s.ng;
    if (t.n[0] >= 0 && t.n[1] >= 0 && t.n[2] >= 0) {
      dvec3 n = b0 * scene.normals[t.n[0]] + b1 * scene.normals[t.n[1]] + b2 * scene.normals[t.n[2]];
      double len = glm::length(n);
      if (len > 0) s.ns = glm::dot(n, s.ng) < 0 ? -n / len : n / len;
    }
    if (t.uv[0] >= 0 && t.uv[1] >= 0 && t.uv[2] >= 0)
      s.uv = b0 * scene.uvs[t.uv[0]] + b1 * scene.uvs[t.uv[1]] + b2 * scene.uvs[t.uv[2]];
    else
      s.uv = dvec2(b1, b2);
    s.material = t.material;
    s.err = 1e-9 * std::max(max_abs(v0), std::max(max_abs(v1), max_abs(v2))) + 1e-12;
  }
  s.front = glm::dot(ray.d, s.ng) < 0;
  if (!s.front) {
    s.ng = -s.ng;
    s.ns = -s.ns;
  }
  return s;
}

void World::sample_area(int prim, double u1, double u2, dvec3& p, dvec3& n) const {
  const Prim& pr = prims[prim];
  if (pr.sphere) {
    // uniform on the whole sphere (Archimedes: z uniform)
    const Sphere& sp = scene.spheres[pr.index];
    double z = 1 - 2 * u1, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u2;
    n = dvec3(r * std::cos(phi), r * std::sin(phi), z);
    p = sp.center + sp.radius * n;
    return;
  }
  const Triangle& t = scene.triangles[pr.index];
  const dvec3 &v0 = scene.positions[t.v[0]], &v1 = scene.positions[t.v[1]],
              &v2 = scene.positions[t.v[2]];
  double su = std::sqrt(u1);
  double b0 = 1 - su, b1 = u2 * su;
  p = b0 * v0 + b1 * v1 + (1 - b0 - b1) * v2;
  n = glm::normalize(glm::cross(v1 - v0, v2 - v0));
}

dvec3 texture_rgb(const Texture& tex, dvec2 uv) {
  if (tex.width <= 0 || tex.height <= 0) return dvec3(0.0);
  auto texel = [&](long x, long y) {
    x %= tex.width;
    if (x < 0) x += tex.width;
    y %= tex.height;
    if (y < 0) y += tex.height;
    const float* t = &tex.rgba[(static_cast<size_t>(y) * tex.width + x) * 4];
    return dvec3(t[0], t[1], t[2]);
  };
  double u = uv.x - std::floor(uv.x), v = uv.y - std::floor(uv.y);
  double x = u * tex.width - 0.5, y = (1 - v) * tex.height - 0.5;  // row 0 is the top
  double fx = std::floor(x), fy = std::floor(y);
  double ax = x - fx, ay = y - fy;
  long ix = static_cast<long>(fx), iy = static_cast<long>(fy);
  return (1 - ay) * ((1 - ax) * texel(ix, iy) + ax * texel(ix + 1, iy)) +
         ay * ((1 - ax) * texel(ix, iy + 1) + ax * texel(ix + 1, iy + 1));
}

}  // namespace lucent::ref
