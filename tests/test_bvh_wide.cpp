// The collapse of the binary SAH tree into wide nodes and leaf blocks (src/bvh/bvh_wide.cpp),
// checked by an independent walk of the result: every node reached once, every primitive in
// exactly one leaf block column with its triangle's vertices, every child box containing its
// whole subtree, unused slots empty, and node count, depth (the kernel's stack bound) and
// statistics consistent; and the choice of each node's children against an exhaustive search
// for the least SAH cost. Traversal agreement with a brute force is in test_bvh_trace.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <vector>

#include "bvh/bvh.hpp"
#include "support/reorder.hpp"
#include "support/test_meshes.hpp"

namespace test_bvh_wide {

namespace {

using lucent::bvh::BuildOptions;
using lucent::bvh::Bvh;

struct Box {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  void grow(const Box& b) {
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], b.lo[a]), hi[a] = std::max(hi[a], b.hi[a]);
  }
};

Box prim_box(const std::vector<lc_triangle>& tris, const std::vector<lc_sphere>& spheres,
             lc_uint ref) {
  Box b;
  if (ref & LC_PRIM_SPHERE_BIT) {
    const lc_sphere& s = spheres[ref & ~LC_PRIM_SPHERE_BIT];
    // the smallest float box that holds the sphere: centre -+ radius rounded outward
    for (int a = 0; a < 3; ++a) {
      const double l = double(s.center[a]) - s.radius, h = double(s.center[a]) + s.radius;
      b.lo[a] = float(l) > l ? std::nextafter(float(l), -INFINITY) : float(l);
      b.hi[a] = float(h) < h ? std::nextafter(float(h), INFINITY) : float(h);
    }
    return b;
  }
  const lc_triangle& t = tris[ref];
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = std::min({t.v0[a], t.v1[a], t.v2[a]});
    b.hi[a] = std::max({t.v0[a], t.v1[a], t.v2[a]});
  }
  return b;
}

struct WideStats {
  std::size_t nodes = 0, leaves = 0, depth = 0, used_slots = 0, mixed_blocks = 0;
};

class Checker {
 public:
  Checker(const Bvh& b, const std::vector<lc_triangle>& tris, const std::vector<lc_sphere>& spheres,
          int max_leaf)
      : b_(b), tris_(tris), spheres_(spheres), max_leaf_(max_leaf) {}

  WideStats run() {
    const std::size_t n = tris_.size() + spheres_.size();
    WideStats st;
    EXPECT_EQ(b_.stats.primitives, n);
    if (n == 0) {
      EXPECT_TRUE(b_.nodes.empty());
      EXPECT_TRUE(b_.leaves.empty());
      return st;
    }
    if (b_.nodes.empty()) {
      ADD_FAILURE() << "no node for " << n << " primitives";
      return st;
    }
    visited_.assign(b_.nodes.size(), 0);
    block_used_.assign(b_.leaves.size(), 0);
    seen_tri_.assign(tris_.size(), 0);
    seen_sphere_.assign(spheres_.size(), 0);
    Box all = node(0, 1, st);
    for (std::size_t i = 0; i < visited_.size(); ++i)
      EXPECT_EQ(visited_[i], 1) << "node " << i << " reached " << visited_[i] << " times";
    for (std::size_t i = 0; i < block_used_.size(); ++i)
      EXPECT_EQ(block_used_[i], 1) << "leaf block " << i << " used " << block_used_[i] << " times";
    for (std::size_t i = 0; i < tris_.size(); ++i) EXPECT_EQ(seen_tri_[i], 1) << "triangle " << i;
    for (std::size_t i = 0; i < spheres_.size(); ++i)
      EXPECT_EQ(seen_sphere_[i], 1) << "sphere " << i;
    for (int a = 0; a < 3; ++a) {  // the scene bounds the Bvh reports
      EXPECT_EQ(b_.bmin[a], all.lo[a]);
      EXPECT_EQ(b_.bmax[a], all.hi[a]);
    }
    st.nodes = b_.nodes.size();
    EXPECT_EQ(b_.stats.nodes, st.nodes);
    EXPECT_EQ(b_.stats.leaves, st.leaves);
    EXPECT_EQ(b_.stats.max_depth, st.depth);
    // the kernel's stack (kernels/bvh/traverse.cl) holds (width - 1) (depth - 1) + width entries
    EXPECT_LE(st.depth, std::size_t(LC_BVH_MAX_DEPTH));
    EXPECT_LE(st.depth, b_.stats.binary_max_depth);
    // a binary tree with L leaves has L - 1 interior nodes; each wide node absorbs at least one
    // and, being full or holding only leaves, at most width - 1 of them
    EXPECT_LE(st.nodes, std::max<std::size_t>(1, st.leaves - 1));
    EXPECT_GE(st.nodes * (LC_BVH_WIDTH - 1) + 1, st.leaves);
    return st;
  }

 private:
  // Checks node `i` at depth `depth` and returns the bounds of its primitives.
  Box node(lc_uint i, std::size_t depth, WideStats& st) {
    Box out;
    if (i >= b_.nodes.size()) {
      ADD_FAILURE() << "node index " << i << " out of range";
      return out;
    }
    if (visited_[i]++) return out;  // reported by run()
    st.depth = std::max(st.depth, depth);
    const lc_bvh_node& nd = b_.nodes[i];
    int used = 0;
    for (int k = 0; k < LC_BVH_WIDTH; ++k) {
      Box box;
      for (int a = 0; a < 3; ++a) {
        box.lo[a] = nd.bounds[2 * a][k];
        box.hi[a] = nd.bounds[2 * a + 1][k];
      }
      lc_uint c = nd.child[k];
      if (c == LC_INVALID) {
        for (int a = 0; a < 3; ++a)
          EXPECT_TRUE(box.lo[a] == INFINITY && box.hi[a] == -INFINITY)
              << "unused slot " << k << " of node " << i << " is not an empty box";
        continue;
      }
      EXPECT_EQ(used, k) << "node " << i << ": used slots should come first";
      ++used;
      Box sub = (c & LC_BVH_LEAF_BIT) ? leaf(c, st) : node(c, depth + 1, st);
      for (int a = 0; a < 3; ++a)
        if (!(box.lo[a] <= sub.lo[a] && box.hi[a] >= sub.hi[a]))
          ADD_FAILURE() << "child " << k << " of node " << i << " does not contain its subtree on "
                        << "axis " << a;
      out.grow(sub);
    }
    st.used_slots += used;
    EXPECT_GE(used, (i == 0 && b_.stats.leaves == 1) ? 1 : 2) << "node " << i;
    return out;
  }

  Box leaf(lc_uint ref, WideStats& st) {
    Box out;
    ++st.leaves;
    lc_uint first = ref & LC_BVH_LEAF_FIRST_MASK;
    lc_uint blocks = ((ref & ~LC_BVH_LEAF_BIT) >> LC_BVH_LEAF_COUNT_SHIFT) + 1;
    if (std::size_t(first) + blocks > b_.leaves.size()) {
      ADD_FAILURE() << "leaf blocks " << first << " + " << blocks << " out of range";
      return out;
    }
    lc_uint count = 0;
    for (lc_uint k = 0; k < blocks; ++k) {
      const lc_bvh_leaf& l = b_.leaves[first + k];
      ++block_used_[first + k];
      bool has_tri = false, has_sphere = false;
      for (int j = 0; j < 4; ++j) {
        lc_uint p = l.prim[j];
        if (p == LC_INVALID) {
          EXPECT_EQ(k, blocks - 1) << "only the last block of a leaf may have unused columns";
          for (int r = 0; r < 9; ++r) EXPECT_EQ(l.v[r][j], 0.0f);
          continue;
        }
        EXPECT_EQ(count, lc_uint(4 * k + j)) << "unused column before a used one";
        ++count;
        if (p & LC_PRIM_SPHERE_BIT) {
          has_sphere = true;
          lc_uint s = p & ~LC_PRIM_SPHERE_BIT;
          if (s >= spheres_.size()) {
            ADD_FAILURE() << "sphere " << s << " out of range";
            continue;
          }
          ++seen_sphere_[s];
          for (int r = 0; r < 9; ++r) EXPECT_EQ(l.v[r][j], 0.0f);
        } else {
          has_tri = true;
          if (p >= tris_.size()) {
            ADD_FAILURE() << "triangle " << p << " out of range";
            continue;
          }
          ++seen_tri_[p];
          const lc_triangle& t = tris_[p];
          for (int a = 0; a < 3; ++a) {
            EXPECT_EQ(l.v[a][j], t.v0[a]);
            EXPECT_EQ(l.v[3 + a][j], t.v1[a]);
            EXPECT_EQ(l.v[6 + a][j], t.v2[a]);
          }
        }
        out.grow(prim_box(tris_, spheres_, p));
      }
      st.mixed_blocks += has_tri && has_sphere;
    }
    EXPECT_GE(count, 1u);
    EXPECT_LE(count, lc_uint(max_leaf_));
    EXPECT_EQ(blocks, (count + 3) / 4) << "a leaf fills as few blocks as it can";
    return out;
  }

  const Bvh& b_;
  const std::vector<lc_triangle>& tris_;
  const std::vector<lc_sphere>& spheres_;
  int max_leaf_;
  std::vector<int> visited_, block_used_, seen_tri_, seen_sphere_;
};

WideStats build_and_check(const std::vector<lc_triangle>& tris,
                          const std::vector<lc_sphere>& spheres, BuildOptions o = {}) {
  Bvh b = lucent::bvh::build(tris, spheres, o);
  return Checker(b, tris, spheres, o.max_leaf_size).run();
}

using lucent::bvh::meshes::random_soup;
using lucent::bvh::meshes::random_spheres;

TEST(BvhWide, EmptyAndSinglePrimitive) {
  build_and_check({}, {});
  WideStats one = build_and_check(random_soup(1, 1, 0.1f), {});
  EXPECT_EQ(one.nodes, 1u);  // a root whose only child is the leaf
  EXPECT_EQ(one.leaves, 1u);
  EXPECT_EQ(one.used_slots, 1u);
  build_and_check({}, random_spheres(1, 2));
  build_and_check(random_soup(3, 3, 0.1f), {});  // one leaf
}

TEST(BvhWide, SoupSpheresAndMixedBlocks) {
  build_and_check(random_soup(5000, 4, 0.05f), {});
  build_and_check({}, random_spheres(3000, 5));
  // spheres and triangles around the same points end up in the same leaf blocks
  WideStats mix = build_and_check(random_soup(2000, 6, 0.02f), random_spheres(2000, 6));
  EXPECT_GT(mix.mixed_blocks, 0u) << "no block mixes spheres and triangles: the test is void";
}

// The leaf blocks are allocated once, at their exact number: a guess of one block per two
// primitives grew by doubling where small sparse primitives get a block each, and a million
// spheres held 1.5 times their blocks for a moment, 20% above the host memory estimate (the BVH
// review).
TEST(BvhWide, LeafBlocksAllocatedExactly) {
  for (const Bvh& b : {lucent::bvh::build({}, random_spheres(3000, 5)),
                       lucent::bvh::build(random_soup(5000, 4, 0.05f), {})}) {
    EXPECT_GT(b.leaves.size(), 0u);
    EXPECT_EQ(b.leaves.capacity(), b.leaves.size());
  }
}

TEST(BvhWide, ClosedMeshesFillTheNodes) {
  auto torus = lucent::bvh::meshes::torus(300, 100, 1.0f, 0.3f, 0.2f).triangles();
  WideStats st = build_and_check(torus, {});
  // nodes are full but those just above the leaves (on average 3.1 of 4 or 4.4 of 8 children
  // per node here)
  EXPECT_GT(double(st.used_slots) / double(st.nodes), 0.5 * LC_BVH_WIDTH);
  build_and_check(lucent::bvh::meshes::icosphere(5).triangles(), {});
}

TEST(BvhWide, LeafSizes) {
  auto t = random_soup(3000, 7, 0.05f);
  auto s = random_spheres(300, 8);
  for (int leaf : {1, 2, 5, 8, 16}) {
    BuildOptions o;
    o.max_leaf_size = leaf;
    build_and_check(t, s, o);
    o.leaf_block = 1;
    build_and_check(t, s, o);
  }
}

// Degenerate inputs: equal centroids (median splits), zero-extent boxes, and exponentially
// spaced primitives whose binary tree is as deep as the builder allows.
TEST(BvhWide, DegenerateInputs) {
  std::vector<lc_triangle> nested;
  for (int i = 0; i < 1000; ++i) {
    float s = 1.0f + i * 0.001f;
    lc_triangle t{};
    t.v0[0] = -s, t.v0[1] = -s, t.v1[0] = 2 * s, t.v1[1] = -s, t.v2[0] = -s, t.v2[1] = 2 * s;
    nested.push_back(t);
  }
  build_and_check(nested, {});
  std::vector<lc_triangle> points(100);
  for (auto& p : points) p.v0[0] = p.v1[0] = p.v2[0] = 1;
  build_and_check(points, {});
  std::vector<lc_triangle> expo = lucent::bvh::meshes::exponential_spacing();
  for (int leaf : {1, 4}) {
    BuildOptions o;
    o.max_leaf_size = leaf;
    build_and_check(expo, {}, o);
  }
}

// reorder_triangles on the wide tree: the blocks' references follow the triangles, their
// vertices stay those of the same triangles.
TEST(BvhWide, ReorderTrianglesKeepsTheBlocksConsistent) {
  auto t = random_soup(3000, 9, 0.05f);
  auto s = random_spheres(500, 10);
  Bvh b = lucent::bvh::build(t, s);
  std::vector<lc_triangle> moved = t;
  std::vector<lc_uint> new_to_old = lucent::bvh::reorder_triangles(b, moved);
  ASSERT_EQ(new_to_old.size(), t.size());
  Checker(b, moved, s, 4).run();
  // leaf order: the blocks, walked in order, reference the triangles 0, 1, 2, ...
  lc_uint next = 0;
  for (const lc_bvh_leaf& l : b.leaves)
    for (lc_uint p : l.prim)
      if (!(p & LC_PRIM_SPHERE_BIT)) {
        EXPECT_EQ(p, next++);
      }
}

// The SAH counts leaf cost in blocks of leaf_block primitives: with blocks of 4 the leaves are
// fuller than with the classic per-primitive cost, on the same triangles.
TEST(BvhWide, BlockCostFillsLeaves) {
  auto t = lucent::bvh::meshes::torus(200, 100, 1.0f, 0.3f, 0.2f).triangles();
  BuildOptions classic;
  classic.leaf_block = 1;
  Bvh a = lucent::bvh::build(t, {}, classic), b = lucent::bvh::build(t, {});
  EXPECT_GT(b.stats.mean_leaf_size, a.stats.mean_leaf_size + 0.5);
  EXPECT_LT(b.leaves.size(), a.leaves.size());
}

// ---- the choice of children: least SAH cost ---------------------------------------------------
// The collapse's cost model (src/bvh/bvh_wide.cpp): a wide node costs the area of its box, a
// leaf the area of its box times its blocks of four triangles plus one per sphere. Here the cost
// of a collapse's result is summed from the wide tree itself, and the least cost of any collapse
// of the same binary tree found by listing, for each node, every set of at most LC_BVH_WIDTH
// descendants that can be its children.

double box_area(const float* lo, const float* hi) {
  double d[3];
  for (int a = 0; a < 3; ++a) d[a] = std::max(0.0, double(hi[a]) - double(lo[a]));
  return 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

double leaf_blocks(std::size_t triangles, std::size_t spheres) {
  return double((triangles + 3) / 4 + spheres);
}

// Cost of the wide tree below node i (box: its box in its parent, or the scene's for the root).
double wide_cost(const Bvh& b, lc_uint i, const float* lo, const float* hi) {
  double c = box_area(lo, hi);
  const lc_bvh_node& nd = b.nodes[i];
  for (int k = 0; k < LC_BVH_WIDTH; ++k) {
    const lc_uint ch = nd.child[k];
    if (ch == LC_INVALID) continue;
    float clo[3], chi[3];
    for (int a = 0; a < 3; ++a) clo[a] = nd.bounds[2 * a][k], chi[a] = nd.bounds[2 * a + 1][k];
    if (!(ch & LC_BVH_LEAF_BIT)) {
      c += wide_cost(b, ch, clo, chi);
      continue;
    }
    std::size_t tri = 0, sph = 0;
    const lc_uint first = ch & LC_BVH_LEAF_FIRST_MASK;
    const lc_uint blocks = ((ch & ~LC_BVH_LEAF_BIT) >> LC_BVH_LEAF_COUNT_SHIFT) + 1;
    for (lc_uint j = first; j < first + blocks; ++j)
      for (lc_uint p : b.leaves[j].prim)
        if (p != LC_INVALID) ++((p & LC_PRIM_SPHERE_BIT) ? sph : tri);
    c += box_area(clo, chi) * leaf_blocks(tri, sph);
  }
  return c;
}

class Exhaustive {
 public:
  explicit Exhaustive(const lucent::bvh::Bvh2& b) : b_(b) {}

  // least cost of the wide tree made from binary node x (a root leaf: the root's only child)
  double root() {
    const lucent::bvh::Node2& n = b_.nodes[0];
    return n.count > 0 ? area(0) + slot(0) : node(0);
  }

  // the greedy rule the collapse used before: open the child of largest area until full
  double greedy(lc_uint x) {
    const lucent::bvh::Node2& n = b_.nodes[x];
    if (n.count > 0) return slot(x);
    std::vector<lc_uint> kids{n.left_first, n.left_first + 1};
    while (kids.size() < std::size_t(LC_BVH_WIDTH)) {
      int best = -1;
      for (std::size_t k = 0; k < kids.size(); ++k)
        if (b_.nodes[kids[k]].count == 0 && (best < 0 || area(kids[k]) > area(kids[best])))
          best = int(k);
      if (best < 0) break;
      const lc_uint first = b_.nodes[kids[best]].left_first;
      kids[best] = first;
      kids.push_back(first + 1);
    }
    double c = area(x);
    for (lc_uint k : kids) c += b_.nodes[k].count > 0 ? slot(k) : greedy(k);
    return c;
  }

 private:
  double area(lc_uint x) const { return box_area(b_.nodes[x].bmin, b_.nodes[x].bmax); }

  // a leaf as a child, or an interior node as a wide node
  double slot(lc_uint x) {
    const lucent::bvh::Node2& n = b_.nodes[x];
    if (n.count == 0) return node(x);
    std::size_t tri = 0, sph = 0;
    for (lc_uint i = 0; i < n.count; ++i)
      ++((b_.prim_refs[n.left_first + i] & LC_PRIM_SPHERE_BIT) ? sph : tri);
    return area(x) * leaf_blocks(tri, sph);
  }

  // every set of at most k nodes that can stand for subtree y: y, or y opened and each child's
  // subtree stood for by such a set
  void frontiers(lc_uint y, std::size_t k, std::vector<std::vector<lc_uint>>& out) const {
    out.push_back({y});
    const lucent::bvh::Node2& n = b_.nodes[y];
    if (n.count > 0 || k < 2) return;
    std::vector<std::vector<lc_uint>> l, r;
    frontiers(n.left_first, k - 1, l);
    frontiers(n.left_first + 1, k - 1, r);
    for (const auto& a : l)
      for (const auto& c : r)
        if (a.size() + c.size() <= k) {
          out.push_back(a);
          out.back().insert(out.back().end(), c.begin(), c.end());
        }
  }

  // least cost of interior node x as a wide node: its area and its children's, over every set of
  // at most LC_BVH_WIDTH descendants that covers its two children's subtrees
  double node(lc_uint x) {
    auto it = memo_.find(x);
    if (it != memo_.end()) return it->second;
    const lucent::bvh::Node2& n = b_.nodes[x];
    std::vector<std::vector<lc_uint>> l, r;
    frontiers(n.left_first, LC_BVH_WIDTH - 1, l);
    frontiers(n.left_first + 1, LC_BVH_WIDTH - 1, r);
    double best = INFINITY;
    for (const auto& a : l)
      for (const auto& c : r) {
        if (a.size() + c.size() > std::size_t(LC_BVH_WIDTH)) continue;
        double sum = 0;
        for (lc_uint y : a) sum += slot(y);
        for (lc_uint y : c) sum += slot(y);
        best = std::min(best, sum);
      }
    return memo_[x] = area(x) + best;
  }

  const lucent::bvh::Bvh2& b_;
  std::map<lc_uint, double> memo_;
};

TEST(BvhWide, ChildrenMinimiseTheSahCost) {
  int greedy_worse = 0, cases = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    for (int leaf : {1, 4}) {
      BuildOptions o;
      o.max_leaf_size = leaf;
      o.threads = 1;
      // clustered soups give unbalanced trees, where the greedy rule and the optimum differ
      auto tris = random_soup(20 + 3 * int(seed), seed, seed % 2 ? 0.05f : 0.3f);
      auto spheres = seed % 3 == 0 ? random_spheres(6, seed) : std::vector<lc_sphere>{};
      lucent::bvh::Bvh2 b2 = lucent::bvh::build_binary(tris, spheres, o);
      Bvh b = lucent::bvh::collapse(b2, tris);
      Checker(b, tris, spheres, leaf).run();
      Exhaustive ex(b2);
      const double got = wide_cost(b, 0, b.bmin, b.bmax), best = ex.root();
      EXPECT_NEAR(got, best, 1e-9 * best) << "seed " << seed << ", leaves of " << leaf;
      const double greedy = ex.greedy(0);
      EXPECT_LE(best, greedy * (1 + 1e-12));
      greedy_worse += best < greedy * (1 - 1e-9);
      ++cases;
    }
  }
  // the check can tell the optimum from the greedy rule (else it would pass either)
  EXPECT_GT(greedy_worse, 0) << "in none of " << cases << " trees";
}

}  // namespace

namespace {

// build() collapses the scratch tree directly, handing back its pages as it goes (bvh_build.cpp);
// collapse(build_binary()) goes through the depth-first copy. The two must give the same tree, bit
// for bit: the renderer uses the first, every other test of the wide tree the second.
TEST(BvhWide, BuildIsTheCollapseOfTheBinaryTreeBitForBit) {
  struct Case {
    int triangles, spheres, leaf;
    unsigned threads, seed;
  };
  // 60,000 triangles: a scratch tree of about 3.7 MiB, past the 1 MiB steps in which its pages go
  for (const Case c :
       {Case{1, 0, 4, 1, 1}, Case{2, 1, 4, 1, 2}, Case{37, 5, 1, 1, 3}, Case{500, 0, 4, 2, 4},
        Case{0, 40, 4, 2, 5}, Case{60000, 3, 4, 2, 6}, Case{60000, 0, 2, 1, 7}}) {
    SCOPED_TRACE(std::to_string(c.triangles) + " triangles, seed " + std::to_string(c.seed));
    BuildOptions o;
    o.max_leaf_size = c.leaf;
    o.threads = int(c.threads);
    auto tris = random_soup(c.triangles, c.seed, 0.05f);
    auto spheres = c.spheres ? random_spheres(c.spheres, c.seed) : std::vector<lc_sphere>{};
    const Bvh direct = lucent::bvh::build(tris, spheres, o);
    const Bvh via = lucent::bvh::collapse(lucent::bvh::build_binary(tris, spheres, o), tris);
    ASSERT_EQ(direct.nodes.size(), via.nodes.size());
    ASSERT_EQ(direct.leaves.size(), via.leaves.size());
    EXPECT_EQ(std::memcmp(direct.nodes.data(), via.nodes.data(),
                          direct.nodes.size() * sizeof(lc_bvh_node)),
              0);
    EXPECT_EQ(std::memcmp(direct.leaves.data(), via.leaves.data(),
                          direct.leaves.size() * sizeof(lc_bvh_leaf)),
              0);
    EXPECT_EQ(std::memcmp(direct.bmin, via.bmin, sizeof direct.bmin), 0);
    EXPECT_EQ(std::memcmp(direct.bmax, via.bmax, sizeof direct.bmax), 0);
    const lucent::bvh::BuildStats &a = direct.stats, &b = via.stats;
    EXPECT_EQ(a.primitives, b.primitives);
    EXPECT_EQ(a.nodes, b.nodes);
    EXPECT_EQ(a.leaves, b.leaves);
    EXPECT_EQ(a.max_depth, b.max_depth);
    EXPECT_EQ(a.max_leaf_size, b.max_leaf_size);
    EXPECT_EQ(a.mean_leaf_size, b.mean_leaf_size);
    EXPECT_EQ(a.sah_cost, b.sah_cost);
    EXPECT_EQ(a.binary_nodes, b.binary_nodes);
    EXPECT_EQ(a.binary_max_depth, b.binary_max_depth);
  }
}

}  // namespace

}  // namespace test_bvh_wide
