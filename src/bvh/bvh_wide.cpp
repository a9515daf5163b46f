// Collapse of the binary SAH tree (bvh_build.cpp) into the wide nodes of kernels/shared/types.h.
// Each wide node starts from the two children of a binary node and repeatedly opens its interior
// child of largest surface area (replacing it by that child's two children) until it holds
// LC_BVH_WIDTH children or only leaves, as in Wald et al., "Getting Rid of Packets" (2008) and
// Embree's BVH4/BVH8 builders. A leaf's primitives (consecutive in prim_refs) go to consecutive
// leaf blocks of 4, with their triangles' vertices in structure-of-arrays form.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "bvh/bvh.hpp"
#include "lucent/error.hpp"

namespace lucent::bvh {

namespace {

double area(const Node2& n) {
  double d[3];
  for (int a = 0; a < 3; ++a) d[a] = std::max(0.0, double(n.bmax[a]) - n.bmin[a]);
  return 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

}  // namespace

Bvh collapse(const Bvh2& b, const std::vector<lc_triangle>& triangles) {
  Bvh out;
  out.stats = b.stats;
  out.stats.binary_nodes = b.stats.nodes;
  out.stats.binary_max_depth = b.stats.max_depth;
  out.stats.nodes = 0;
  out.stats.max_depth = 0;
  if (b.nodes.empty()) return out;
  // a leaf's blocks start at most at prim_refs.size() - 1 (one block per primitive at worst)
  if (b.prim_refs.size() > std::size_t(LC_BVH_LEAF_FIRST_MASK) + 1)
    throw Error("scene: " + std::to_string(b.prim_refs.size()) +
                " primitives, more than the BVH can reference (" +
                std::to_string(std::size_t(LC_BVH_LEAF_FIRST_MASK) + 1) + ")");
  auto add_leaf = [&](const Node2& c) {
    lc_uint first = static_cast<lc_uint>(out.leaves.size());
    lc_uint blocks = (c.count + 3) / 4;
    for (lc_uint k = 0; k < blocks; ++k) {
      lc_bvh_leaf l{};
      for (lc_uint j = 0; j < 4; ++j) {
        lc_uint i = 4 * k + j;
        if (i >= c.count) {
          l.prim[j] = LC_INVALID;
          continue;
        }
        lc_uint ref = b.prim_refs[c.left_first + i];
        l.prim[j] = ref;
        if (ref & LC_PRIM_SPHERE_BIT) continue;
        if (ref >= triangles.size())
          throw std::logic_error("bvh::collapse: the tree was not built over these triangles");
        const lc_triangle& t = triangles[ref];
        for (int a = 0; a < 3; ++a) {
          l.v[a][j] = t.v0[a];
          l.v[3 + a][j] = t.v1[a];
          l.v[6 + a][j] = t.v2[a];
        }
      }
      out.leaves.push_back(l);
    }
    return LC_BVH_LEAF_BIT | ((blocks - 1) << LC_BVH_LEAF_COUNT_SHIFT) | first;
  };
  const Node2& root = b.nodes[0];
  for (int a = 0; a < 3; ++a) out.bmin[a] = root.bmin[a], out.bmax[a] = root.bmax[a];

  struct Item {
    lc_uint binary, wide, depth;
  };
  std::vector<Item> stack{{0, 0, 1}};
  out.nodes.reserve(b.nodes.size() / 2 + 1);
  out.leaves.reserve(b.prim_refs.size() / 2 + 1);
  out.nodes.emplace_back();
  std::size_t leaves = 0, max_leaf = 0;
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    out.stats.max_depth = std::max<std::size_t>(out.stats.max_depth, it.depth);
    // the binary nodes that become this node's children
    lc_uint kids[LC_BVH_WIDTH];
    int n = 0;
    const Node2& bn = b.nodes[it.binary];
    if (bn.count > 0) {  // a root leaf: the only child of the root
      kids[n++] = it.binary;
    } else {
      kids[n++] = bn.left_first;
      kids[n++] = bn.left_first + 1;
    }
    while (n < LC_BVH_WIDTH) {
      int best = -1;
      double best_area = -1;
      for (int k = 0; k < n; ++k) {
        const Node2& c = b.nodes[kids[k]];
        if (c.count == 0 && area(c) > best_area) best = k, best_area = area(c);
      }
      if (best < 0) break;
      lc_uint first = b.nodes[kids[best]].left_first;
      kids[best] = first;
      kids[n++] = first + 1;
    }
    // children that are interior nodes get consecutive node indices
    lc_uint next = static_cast<lc_uint>(out.nodes.size());
    int interior = 0;
    for (int k = 0; k < n; ++k) interior += b.nodes[kids[k]].count == 0;
    out.nodes.resize(out.nodes.size() + interior);
    lc_bvh_node& w = out.nodes[it.wide];
    for (int k = 0; k < LC_BVH_WIDTH; ++k) {
      if (k >= n) {
        for (int a = 0; a < 3; ++a) {
          w.bounds[2 * a][k] = INFINITY;
          w.bounds[2 * a + 1][k] = -INFINITY;
        }
        w.child[k] = LC_INVALID;
        w.pad[k] = 0;
        continue;
      }
      const Node2& c = b.nodes[kids[k]];
      for (int a = 0; a < 3; ++a) {
        w.bounds[2 * a][k] = c.bmin[a];
        w.bounds[2 * a + 1][k] = c.bmax[a];
      }
      w.pad[k] = 0;
      if (c.count > 0) {
        w.child[k] = add_leaf(c);
        ++leaves;
        max_leaf = std::max<std::size_t>(max_leaf, c.count);
      } else {
        w.child[k] = next++;
      }
    }
    // depth-first: the first child's subtree is processed first
    for (int k = n - 1; k >= 0; --k)
      if (!(w.child[k] & LC_BVH_LEAF_BIT)) stack.push_back({kids[k], w.child[k], it.depth + 1});
  }
  out.stats.nodes = out.nodes.size();
  out.stats.leaves = leaves;
  out.stats.max_leaf_size = max_leaf;
  out.stats.mean_leaf_size = leaves ? double(b.prim_refs.size()) / double(leaves) : 0;
  return out;
}

}  // namespace lucent::bvh
