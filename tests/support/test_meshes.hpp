#pragma once
// Generated meshes for the BVH tests and the benchmark: closed, shared-vertex triangle meshes
// (every edge belongs to exactly two triangles), as lc_triangle arrays; and random triangle soups
// and sphere sets.
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "shared/types.h"

namespace lucent::bvh::meshes {

struct IndexedMesh {
  std::vector<std::array<float, 3>> positions;
  std::vector<std::array<lc_uint, 3>> faces;

  std::vector<lc_triangle> triangles() const {
    std::vector<lc_triangle> out(faces.size());
    for (std::size_t i = 0; i < faces.size(); ++i) {
      lc_triangle& t = out[i];
      t = lc_triangle{};
      for (int a = 0; a < 3; ++a) {
        t.v0[a] = positions[faces[i][0]][a];
        t.v1[a] = positions[faces[i][1]][a];
        t.v2[a] = positions[faces[i][2]][a];
      }
      t.light = LC_INVALID;
    }
    return out;
  }
};

/// Icosahedron subdivided `levels` times, projected onto the sphere (20 * 4^levels faces).
inline IndexedMesh icosphere(int levels, float radius = 1.0f, const float* center = nullptr) {
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<std::array<double, 3>> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0},
                                          {0, -1, p}, {0, 1, p}, {0, -1, -p}, {0, 1, -p},
                                          {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  std::vector<std::array<lc_uint, 3>> f = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& x : v) {
    double l = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (double& c : x) c /= l;
  }
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<lc_uint, lc_uint>, lc_uint> mid;
    auto midpoint = [&](lc_uint a, lc_uint b) {
      auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      std::array<double, 3> m;
      for (int c = 0; c < 3; ++c) m[c] = 0.5 * (v[a][c] + v[b][c]);
      double l = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
      for (double& c : m) c /= l;
      v.push_back(m);
      lc_uint id = static_cast<lc_uint>(v.size() - 1);
      mid.emplace(key, id);
      return id;
    };
    std::vector<std::array<lc_uint, 3>> next;
    next.reserve(f.size() * 4);
    for (auto& t : f) {
      lc_uint a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      next.push_back({t[0], a, c});
      next.push_back({t[1], b, a});
      next.push_back({t[2], c, b});
      next.push_back({a, b, c});
    }
    f.swap(next);
  }
  IndexedMesh m;
  for (auto& x : v) {
    std::array<float, 3> q;
    for (int c = 0; c < 3; ++c) q[c] = static_cast<float>(x[c] * radius + (center ? center[c] : 0));
    m.positions.push_back(q);
  }
  m.faces = f;
  return m;
}

/// Torus around the y axis: nu segments around it, nv around the tube (2 nu nv faces). With
/// bump > 0 the tube radius varies with a few sine waves (a bumpier, less regular surface).
inline IndexedMesh torus(int nu, int nv, float major = 1.0f, float minor = 0.3f,
                         float bump = 0.0f) {
  IndexedMesh m;
  const double two_pi = 2 * M_PI;
  for (int i = 0; i < nu; ++i) {
    double u = two_pi * i / nu;
    for (int j = 0; j < nv; ++j) {
      double w = two_pi * j / nv;
      double r = minor * (1 + bump * std::sin(7 * u) * std::sin(5 * w) +
                          0.5 * bump * std::sin(23 * u + 3 * w));
      double x = (major + r * std::cos(w)) * std::cos(u);
      double z = (major + r * std::cos(w)) * std::sin(u);
      double y = r * std::sin(w);
      m.positions.push_back({float(x), float(y), float(z)});
    }
  }
  auto id = [&](int i, int j) { return static_cast<lc_uint>((i % nu) * nv + (j % nv)); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

/// n small triangles at uniform random points of the unit cube, vertices within +-size of them.
inline std::vector<lc_triangle> random_soup(int n, unsigned seed, float size = 0.05f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1), s(-size, size);
  std::vector<lc_triangle> out;
  for (int i = 0; i < n; ++i) {
    lc_triangle t{};
    float c[3] = {u(rng), u(rng), u(rng)};
    for (int a = 0; a < 3; ++a) {
      t.v0[a] = c[a] + s(rng);
      t.v1[a] = c[a] + s(rng);
      t.v2[a] = c[a] + s(rng);
    }
    out.push_back(t);
  }
  return out;
}

/// n spheres of radius 0.005-0.05 at uniform random points of the unit cube.
inline std::vector<lc_sphere> random_spheres(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1), r(0.005f, 0.05f);
  std::vector<lc_sphere> out;
  for (int i = 0; i < n; ++i) {
    lc_sphere s{};
    s.center[0] = u(rng), s.center[1] = u(rng), s.center[2] = u(rng);
    s.radius = r(rng);
    out.push_back(s);
  }
  return out;
}

/// 135 triangles at exponentially spaced positions 40^k, k = -22..22, along each axis in turn:
/// binned SAH splits peel off a few primitives per level (a worst case for the tree's depth).
inline std::vector<lc_triangle> exponential_spacing() {
  std::vector<lc_triangle> out;
  for (int k = -22; k <= 22; ++k)
    for (int a = 0; a < 3; ++a) {
      float x = std::pow(40.0f, float(k));
      lc_triangle t{};
      t.v0[a] = x, t.v1[a] = x * 1.1f, t.v2[a] = x;
      t.v1[(a + 1) % 3] = x * 0.1f, t.v2[(a + 2) % 3] = x * 0.1f;
      out.push_back(t);
    }
  return out;
}

}  // namespace lucent::bvh::meshes
