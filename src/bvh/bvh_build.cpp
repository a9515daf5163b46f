// Placeholder builder (object median split) until the binned SAH builder lands.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "bvh/bvh.hpp"

namespace lucent::bvh {

namespace {

struct Box {
  float lo[3] = {INFINITY, INFINITY, INFINITY};
  float hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  void grow(const float* p) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  void grow(const Box& b) {
    grow(b.lo);
    grow(b.hi);
  }
  double area() const {
    double d[3];
    for (int a = 0; a < 3; ++a) d[a] = std::max(0.0, double(hi[a]) - lo[a]);
    return 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
  }
};

}  // namespace

double sah_cost(const std::vector<lc_bvh_node>& nodes) {
  if (nodes.empty()) return 0;
  auto area = [](const lc_bvh_node& n) {
    double d[3];
    for (int a = 0; a < 3; ++a) d[a] = std::max(0.0, double(n.bmax[a]) - n.bmin[a]);
    return 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
  };
  double root = area(nodes[0]);
  if (root <= 0) return 0;
  double cost = 0;
  for (const auto& n : nodes) cost += area(n) / root * (n.count ? double(n.count) : 1.0);
  return cost;
}

Bvh build(const std::vector<lc_triangle>& tris, const std::vector<lc_sphere>& spheres,
          const BuildOptions& options) {
  auto t0 = std::chrono::steady_clock::now();
  Bvh out;
  std::vector<Box> boxes;
  std::vector<lc_uint> refs;
  for (size_t i = 0; i < tris.size(); ++i) {
    Box b;
    b.grow(tris[i].v0);
    b.grow(tris[i].v1);
    b.grow(tris[i].v2);
    boxes.push_back(b);
    refs.push_back(static_cast<lc_uint>(i));
  }
  for (size_t i = 0; i < spheres.size(); ++i) {
    Box b;
    const lc_sphere& s = spheres[i];
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = s.center[a] - s.radius;
      b.hi[a] = s.center[a] + s.radius;
    }
    boxes.push_back(b);
    refs.push_back(static_cast<lc_uint>(i) | LC_PRIM_SPHERE_BIT);
  }
  std::vector<lc_uint> order(boxes.size());
  std::iota(order.begin(), order.end(), 0u);
  if (order.empty()) return out;
  struct Task {
    size_t node, begin, end, depth;
  };
  out.nodes.push_back({});
  std::vector<Task> stack{{0, 0, order.size(), 1}};
  while (!stack.empty()) {
    Task t = stack.back();
    stack.pop_back();
    Box b, cb;
    for (size_t i = t.begin; i < t.end; ++i) {
      b.grow(boxes[order[i]]);
      float c[3];
      for (int a = 0; a < 3; ++a) c[a] = 0.5f * (boxes[order[i]].lo[a] + boxes[order[i]].hi[a]);
      cb.grow(c);
    }
    lc_bvh_node& n = out.nodes[t.node];
    for (int a = 0; a < 3; ++a) {
      n.bmin[a] = b.lo[a];
      n.bmax[a] = b.hi[a];
    }
    size_t count = t.end - t.begin;
    out.stats.max_depth = std::max(out.stats.max_depth, t.depth);
    if (count <= static_cast<size_t>(options.max_leaf_size)) {
      n.left_first = static_cast<lc_uint>(t.begin);
      n.count = static_cast<lc_uint>(count);
      continue;
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (cb.hi[a] - cb.lo[a] > cb.hi[axis] - cb.lo[axis]) axis = a;
    size_t mid = (t.begin + t.end) / 2;
    std::nth_element(order.begin() + t.begin, order.begin() + mid, order.begin() + t.end,
                     [&](lc_uint x, lc_uint y) {
                       return boxes[x].lo[axis] + boxes[x].hi[axis] < boxes[y].lo[axis] + boxes[y].hi[axis];
                     });
    size_t left = out.nodes.size();
    out.nodes[t.node].left_first = static_cast<lc_uint>(left);
    out.nodes[t.node].count = 0;
    out.nodes.push_back({});
    out.nodes.push_back({});
    stack.push_back({left + 1, mid, t.end, t.depth + 1});
    stack.push_back({left, t.begin, mid, t.depth + 1});
  }
  out.prim_refs.resize(order.size());
  for (size_t i = 0; i < order.size(); ++i) out.prim_refs[i] = refs[order[i]];
  out.stats.primitives = order.size();
  out.stats.nodes = out.nodes.size();
  for (const auto& n : out.nodes)
    if (n.count) {
      ++out.stats.leaves;
      out.stats.max_leaf_size = std::max<size_t>(out.stats.max_leaf_size, n.count);
    }
  out.stats.mean_leaf_size = double(order.size()) / double(out.stats.leaves);
  out.stats.sah_cost = sah_cost(out.nodes);
  out.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace lucent::bvh
