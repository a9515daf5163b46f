// Collapse of the binary SAH tree (bvh_build.cpp) into the wide nodes of kernels/shared/types.h.
// Each wide node is made from an interior binary node by opening it and, where that lowers the
// wide tree's SAH cost, its descendants (replacing a node by its two children), up to
// LC_BVH_WIDTH children: the choice of Ylitie et al. (2017), by dynamic programming over the
// binary tree (OptimalCollapse). It replaced the greedy rule of Wald et al. (2008) and Embree's
// builders, opening the child of largest area until the node is full: a third fewer nodes on
// the dragon box and its renders about 4% faster (BENCHMARKS.md). A leaf's primitives
// (consecutive in prim_refs) go to consecutive leaf blocks of 4, with their triangles' vertices
// in structure-of-arrays form.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "bvh/bvh.hpp"
#include "bvh/sah_builder.hpp"
#include "lucent/error.hpp"

namespace lucent::bvh {

namespace {

double area(const Node2& n) {
  double d[3];
  for (int a = 0; a < 3; ++a) d[a] = std::max(0.0, double(n.bmax[a]) - n.bmin[a]);
  return 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

// Which binary nodes become the children of each wide node: those that minimise the SAH cost of
// the wide tree (Ylitie, Karras and Laine 2017, "Efficient incoherent ray traversal on GPUs
// through compressed wide BVHs", section 4.1), with this kernel's costs: a wide node costs its
// area times one test of its children's boxes, a leaf its area times its blocks of four triangles
// plus one per sphere (as the SAH build counts them); one test of a wide node and one leaf block
// take about the same instructions on AVX2. cost(x, k), the least cost of binary subtree x in at
// most k child slots, is x as one child (a leaf, or a wide node made by opening x) or, for k >= 2,
// x opened with its two children sharing the k slots. Solved bottom-up; only each interior node's
// choices (9 bytes, kept by the index of its children's pair: a leaf has none) are kept, the costs
// live on the recursion, which the binary depth bounds (LC_BVH_MAX_DEPTH).
class OptimalCollapse {
 public:
  // nodes: the binary tree (root 0), of `slots` nodes at most
  OptimalCollapse(const Node2* nodes, std::size_t slots, const std::vector<lc_uint>& prim_refs)
      : nodes_(nodes), prim_refs_(prim_refs), split_(slots / 2 + 1) {
    solve(0);
  }

  /// The leaf blocks of the tree: one per 4 primitives of each leaf, rounded up.
  std::size_t blocks() const { return blocks_; }

  // The binary nodes that become the children of the wide node made from interior node x, in
  // the binary tree's order; returns how many (2 to LC_BVH_WIDTH).
  int children(lc_uint x, lc_uint* out) const {
    int n = 0;
    const Node2& bn = nodes_[x];
    const Split& sp = split_[bn.left_first / 2];
    collect(bn.left_first, sp[0], out, n);
    collect(bn.left_first + 1, LC_BVH_WIDTH - sp[0], out, n);
    return n;
  }

 private:
  // cost[k] for k = 1 .. LC_BVH_WIDTH (cost[0] unused)
  struct Costs {
    double c[LC_BVH_WIDTH + 1];
  };
  // split_[x][k], k >= 2: 0 when x stays one child in k slots, else its left child's share of
  // the k slots when x is opened; split_[x][0]: the left child's share in the wide node made from
  // x
  struct Split {
    unsigned char a[LC_BVH_WIDTH + 1];
    unsigned char operator[](int k) const { return a[k]; }
  };

  double leaf_cost(const Node2& n) const {
    std::size_t tri = 0, sph = 0;
    for (lc_uint i = 0; i < n.count; ++i)
      ++((prim_refs_[n.left_first + i] & LC_PRIM_SPHERE_BIT) ? sph : tri);
    return double((tri + 3) / 4 + sph);
  }

  // the least cost of two children (costs l, r) sharing k >= 2 slots; best: the left's share
  static double shared(const Costs& l, const Costs& r, int k, unsigned char& best) {
    double m = std::numeric_limits<double>::infinity();
    for (int a = 1; a < k; ++a)
      if (l.c[a] + r.c[k - a] < m) m = l.c[a] + r.c[k - a], best = static_cast<unsigned char>(a);
    return m;
  }

  Costs solve(lc_uint x) {
    const Node2& n = nodes_[x];
    Costs out;
    out.c[0] = 0;
    if (n.count > 0) {
      blocks_ += (n.count + 3) / 4;
      std::fill(out.c + 1, out.c + LC_BVH_WIDTH + 1, area(n) * leaf_cost(n));
      return out;
    }
    const Costs l = solve(n.left_first), r = solve(n.left_first + 1);
    // children pairs start at distinct even (depth-first copy) or odd (scratch tree) indices
    Split& sp = split_[n.left_first / 2];
    std::fill(std::begin(sp.a), std::end(sp.a), 0);
    const double as_node = area(n) + shared(l, r, LC_BVH_WIDTH, sp.a[0]);
    out.c[1] = as_node;
    for (int k = 2; k <= LC_BVH_WIDTH; ++k) {
      unsigned char a = 0;
      const double opened = shared(l, r, k, a);
      out.c[k] = std::min(as_node, opened);
      sp.a[k] = opened < as_node ? a : 0;
    }
    return out;
  }

  void collect(lc_uint x, int k, lc_uint* out, int& n) const {
    const Node2& bn = nodes_[x];
    const unsigned char a = k >= 2 && bn.count == 0 ? split_[bn.left_first / 2][k] : 0;
    if (a == 0) {
      out[n++] = x;
      return;
    }
    collect(bn.left_first, a, out, n);
    collect(bn.left_first + 1, k - a, out, n);
  }

  const Node2* nodes_;
  const std::vector<lc_uint>& prim_refs_;
  std::vector<Split> split_;
  std::size_t blocks_ = 0;
};

}  // namespace

namespace detail {

Bvh collapse_nodes(const Node2* nodes, std::size_t slots, std::size_t flat_size,
                   const std::vector<lc_uint>& prim_refs, const BuildStats& stats,
                   Span<lc_triangle> triangles, ScratchNodes* release) {
  Bvh out;
  out.stats = stats;
  out.stats.binary_nodes = stats.nodes;
  out.stats.binary_max_depth = stats.max_depth;
  out.stats.nodes = 0;
  out.stats.max_depth = 0;
  if (slots == 0) return out;
  // a leaf's blocks start at most at prim_refs.size() - 1 (one block per primitive at worst)
  if (prim_refs.size() > std::size_t(LC_BVH_LEAF_FIRST_MASK) + 1)
    throw Error("scene: " + std::to_string(prim_refs.size()) +
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
        lc_uint ref = prim_refs[c.left_first + i];
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
  const Node2& root = nodes[0];
  for (int a = 0; a < 3; ++a) out.bmin[a] = root.bmin[a], out.bmax[a] = root.bmax[a];

  struct Item {
    lc_uint binary, wide, depth;
  };
  const OptimalCollapse optimal(nodes, slots, prim_refs);
  std::vector<Item> stack{{0, 0, 1}};
  // (as many as the depth-first copy's size gives, scratch tree or not: the same block)
  out.nodes.reserve(flat_size / 2 + 1);
  // every binary leaf becomes one wide leaf of ceil(count / 4) blocks: reserved exactly (a guess
  // of one block per 2 primitives grew by doubling where sparse primitives get a block each, and
  // held 1.5 times the blocks for a moment: a million small spheres peaked 20% above the host
  // memory estimate, resources.cpp)
  out.leaves.reserve(optimal.blocks());
  out.nodes.emplace_back();
  std::size_t leaves = 0, max_leaf = 0, steps = 0;
  while (!stack.empty()) {
    // what is left to read lies at and after the binary nodes on the stack (a node's descendants
    // follow it): the pages before them go back
    if (release && ++steps % 64 == 0) {
      lc_uint low = stack.back().binary;
      for (const Item& s : stack) low = std::min(low, s.binary);
      release->release_below(low);
    }
    Item it = stack.back();
    stack.pop_back();
    out.stats.max_depth = std::max<std::size_t>(out.stats.max_depth, it.depth);
    // the binary nodes that become this node's children
    lc_uint kids[LC_BVH_WIDTH];
    int n = 0;
    const Node2& bn = nodes[it.binary];
    if (bn.count > 0) {  // a root leaf: the only child of the root
      kids[n++] = it.binary;
    } else {
      n = optimal.children(it.binary, kids);
    }
    // children that are interior nodes get consecutive node indices
    lc_uint next = static_cast<lc_uint>(out.nodes.size());
    int interior = 0;
    for (int k = 0; k < n; ++k) interior += nodes[kids[k]].count == 0;
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
      const Node2& c = nodes[kids[k]];
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
  out.stats.mean_leaf_size = leaves ? double(prim_refs.size()) / double(leaves) : 0;
  return out;
}

}  // namespace detail

Bvh collapse(const Bvh2& b, Span<lc_triangle> triangles) {
  return detail::collapse_nodes(b.nodes.data(), b.nodes.size(), b.nodes.size(), b.prim_refs,
                                b.stats, triangles, nullptr);
}

}  // namespace lucent::bvh
