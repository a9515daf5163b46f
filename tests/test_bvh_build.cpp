// Host-side invariants of the binary BVH builder (src/bvh/bvh_build.cpp), checked by an
// independent walk of the flattened tree: every primitive referenced exactly once, each child box
// inside its parent's, every primitive inside its leaf's box, leaf sizes within the limit, the
// depth-first layout with adjacent children, the depth cap the kernel stack relies on, and the
// statistics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "bvh/bvh.hpp"
#include "support/reorder.hpp"
#include "support/test_meshes.hpp"

namespace test_bvh_build {

namespace {

using lucent::bvh::BuildOptions;
using Bvh = lucent::bvh::Bvh2;
using lucent::bvh::Node2;

lc_triangle tri(float ax, float ay, float az, float bx, float by, float bz, float cx, float cy,
                float cz) {
  lc_triangle t{};
  t.v0[0] = ax, t.v0[1] = ay, t.v0[2] = az;
  t.v1[0] = bx, t.v1[1] = by, t.v1[2] = bz;
  t.v2[0] = cx, t.v2[1] = cy, t.v2[2] = cz;
  return t;
}

using lucent::bvh::meshes::random_soup;
using lucent::bvh::meshes::random_spheres;

// The bounds of primitive `ref`, computed here, exactly (in double): a leaf's float box must hold
// the whole sphere. Rounded to the nearest float, centre +- radius can fall inside the sphere,
// and the traversal then misses rays that graze it (5% of the radius at 1e6 from the origin).
void prim_box(const std::vector<lc_triangle>& tris, const std::vector<lc_sphere>& spheres,
              lc_uint ref, double* lo, double* hi) {
  if (ref & LC_PRIM_SPHERE_BIT) {
    const lc_sphere& s = spheres[ref & ~LC_PRIM_SPHERE_BIT];
    for (int a = 0; a < 3; ++a)
      lo[a] = double(s.center[a]) - std::fabs(double(s.radius)),
      hi[a] = double(s.center[a]) + std::fabs(double(s.radius));
    return;
  }
  const lc_triangle& t = tris[ref];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::min({t.v0[a], t.v1[a], t.v2[a]});
    hi[a] = std::max({t.v0[a], t.v1[a], t.v2[a]});
  }
}

double node_area(const Node2& n) {
  double d[3];
  for (int a = 0; a < 3; ++a) d[a] = std::max(0.0, double(n.bmax[a]) - n.bmin[a]);
  return 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

// Walks the tree and checks every invariant; returns the number of failures (each reported).
void check_bvh(const Bvh& b, const std::vector<lc_triangle>& tris,
               const std::vector<lc_sphere>& spheres, int max_leaf) {
  const std::size_t n = tris.size() + spheres.size();
  ASSERT_EQ(b.stats.primitives, n);
  if (n == 0) {
    EXPECT_TRUE(b.nodes.empty());
    EXPECT_TRUE(b.prim_refs.empty());
    return;
  }
  ASSERT_FALSE(b.nodes.empty());
  ASSERT_EQ(b.prim_refs.size(), n);
  std::vector<int> seen_tri(tris.size(), 0), seen_sphere(spheres.size(), 0);
  std::vector<int> visited(b.nodes.size(), 0);
  struct Item {
    lc_uint node;
    std::size_t depth;
  };
  // depth-first layout: the children of the k-th interior node met in preorder are the pair that
  // follows all pairs of the interior nodes before it; pairs start at even indices, node 1 being
  // an unreferenced empty padding node when the root is not a leaf
  std::vector<Item> stack{{0, 1}};
  lc_uint expected_pair = 2;
  if (b.nodes[0].count == 0) {
    ASSERT_GE(b.nodes.size(), 4u);
    const Node2& pad = b.nodes[1];
    EXPECT_EQ(pad.count, 0u);
    EXPECT_GT(pad.bmin[0], pad.bmax[0]) << "the padding node should be an empty box";
    visited[1] = 1;
  } else {
    EXPECT_EQ(b.nodes.size(), 1u);
  }
  std::size_t leaves = 0, max_depth = 0, max_leaf_seen = 0;
  double sah = 0, root_area = node_area(b.nodes[0]);
  int failures = 0;
  while (!stack.empty() && failures < 10) {
    Item it = stack.back();
    stack.pop_back();
    ASSERT_LT(it.node, b.nodes.size());
    const Node2& nd = b.nodes[it.node];
    ASSERT_EQ(visited[it.node]++, 0) << "node " << it.node << " reached twice";
    max_depth = std::max(max_depth, it.depth);
    if (root_area > 0) sah += node_area(nd) / root_area * (nd.count ? nd.count : 1.0);
    if (nd.count == 0) {
      EXPECT_EQ(nd.left_first % 2, 0u) << "pair of node " << it.node;
    }
    if (nd.count == 0) {
      ASSERT_EQ(nd.left_first, expected_pair) << "node " << it.node << ": not depth-first";
      expected_pair += 2;
      ASSERT_LT(nd.left_first + 1, b.nodes.size());
      for (lc_uint c = nd.left_first; c <= nd.left_first + 1; ++c)
        for (int a = 0; a < 3; ++a) {
          if (!(b.nodes[c].bmin[a] >= nd.bmin[a] && b.nodes[c].bmax[a] <= nd.bmax[a])) {
            ADD_FAILURE() << "child " << c << " of node " << it.node << " leaves its box on axis "
                          << a;
            ++failures;
          }
        }
      stack.push_back({nd.left_first + 1, it.depth + 1});
      stack.push_back({nd.left_first, it.depth + 1});
      continue;
    }
    ++leaves;
    max_leaf_seen = std::max<std::size_t>(max_leaf_seen, nd.count);
    EXPECT_LE(nd.count, static_cast<lc_uint>(max_leaf)) << "leaf " << it.node;
    ASSERT_LE(std::size_t(nd.left_first) + nd.count, b.prim_refs.size()) << "leaf " << it.node;
    for (lc_uint i = nd.left_first; i < nd.left_first + nd.count; ++i) {
      lc_uint ref = b.prim_refs[i];
      if (ref & LC_PRIM_SPHERE_BIT) {
        ASSERT_LT(ref & ~LC_PRIM_SPHERE_BIT, spheres.size());
        ++seen_sphere[ref & ~LC_PRIM_SPHERE_BIT];
      } else {
        ASSERT_LT(ref, tris.size());
        ++seen_tri[ref];
      }
      double lo[3], hi[3];
      prim_box(tris, spheres, ref, lo, hi);
      for (int a = 0; a < 3; ++a)
        if (!(lo[a] >= nd.bmin[a] && hi[a] <= nd.bmax[a])) {
          ADD_FAILURE() << "primitive " << ref << " outside leaf " << it.node << " on axis " << a;
          ++failures;
        }
    }
  }
  for (std::size_t i = 0; i < tris.size(); ++i)
    ASSERT_EQ(seen_tri[i], 1) << "triangle " << i << " referenced " << seen_tri[i] << " times";
  for (std::size_t i = 0; i < spheres.size(); ++i)
    ASSERT_EQ(seen_sphere[i], 1) << "sphere " << i << " referenced " << seen_sphere[i] << " times";
  for (std::size_t i = 0; i < visited.size(); ++i)
    ASSERT_EQ(visited[i], 1) << "node " << i << " unreachable";
  EXPECT_LE(max_depth, 64u) << "deeper than the kernel's traversal stack";
  const auto& s = b.stats;
  EXPECT_EQ(s.nodes, b.nodes.size() - (b.nodes.size() > 1 ? 1 : 0));  // without the padding
  EXPECT_EQ(s.leaves, leaves);
  EXPECT_EQ(s.nodes, 2 * leaves - 1);
  EXPECT_EQ(s.max_depth, max_depth);
  EXPECT_EQ(s.max_leaf_size, max_leaf_seen);
  EXPECT_NEAR(s.mean_leaf_size, double(n) / leaves, 1e-9);
  EXPECT_NEAR(s.sah_cost, sah, 1e-9 * std::max(1.0, sah));
  EXPECT_GE(s.seconds, 0.0);
}

void build_and_check(const std::vector<lc_triangle>& tris, const std::vector<lc_sphere>& spheres,
                     BuildOptions o = {}) {
  Bvh b = lucent::bvh::build_binary(tris, spheres, o);
  check_bvh(b, tris, spheres, o.max_leaf_size);
}

TEST(BvhBuild, NoPrimitiveGivesAnEmptyTree) { build_and_check({}, {}); }

// A primitive with non-finite bounds (a NaN sphere, which validate_scene lets through: it is
// never hit) stays out of the tree, and the others keep their boxes. Growing a box by a NaN bound
// once replaced it by the next finite one (SSE min/max return their second operand): sphere 0
// fell outside every box and was never hit.
TEST(BvhBuild, NonFinitePrimitivesStayOutAndTheOthersKeepTheirBoxes) {
  auto sphere = [](float x, float r) {
    lc_sphere s{};
    s.center[0] = x;
    s.radius = r;
    return s;
  };
  const float nan = std::nanf("");
  std::vector<lc_sphere> all{sphere(-50, 1), sphere(nan, 1), sphere(-4, 1),
                             sphere(5, 1),   sphere(6, 1),   sphere(0, nan)};
  std::vector<lc_sphere> finite{all[0], all[2], all[3], all[4]};
  Bvh b = lucent::bvh::build_binary({}, all);
  EXPECT_EQ(b.prim_refs.size(), 4u);
  std::vector<lc_uint> refs = b.prim_refs;
  std::sort(refs.begin(), refs.end());
  EXPECT_EQ(refs, (std::vector<lc_uint>{0 | LC_PRIM_SPHERE_BIT, 2 | LC_PRIM_SPHERE_BIT,
                                        3 | LC_PRIM_SPHERE_BIT, 4 | LC_PRIM_SPHERE_BIT}));
  EXPECT_EQ(b.nodes[0].bmin[0], -51.0f);
  EXPECT_EQ(b.nodes[0].bmax[0], 7.0f);
  // every kept sphere inside the box of the leaf that holds it
  for (const Node2& nd : b.nodes)
    for (lc_uint i = nd.left_first; nd.count && i < nd.left_first + nd.count; ++i) {
      const lc_sphere& s = all[b.prim_refs[i] & ~LC_PRIM_SPHERE_BIT];
      EXPECT_LE(nd.bmin[0], s.center[0] - s.radius) << "sphere at " << s.center[0];
      EXPECT_GE(nd.bmax[0], s.center[0] + s.radius) << "sphere at " << s.center[0];
    }
  // only NaN: an empty tree
  EXPECT_TRUE(lucent::bvh::build_binary({}, std::vector<lc_sphere>{sphere(nan, 1)}).nodes.empty());
}

TEST(BvhBuild, OnePrimitiveIsARootLeaf) {
  std::vector<lc_triangle> t{tri(0, 0, 0, 1, 0, 0, 0, 1, 0)};
  Bvh b = lucent::bvh::build_binary(t, {});
  check_bvh(b, t, {}, 4);
  ASSERT_EQ(b.nodes.size(), 1u);
  EXPECT_EQ(b.nodes[0].count, 1u);
  std::vector<lc_sphere> s = random_spheres(1, 3);
  build_and_check({}, s);
}

TEST(BvhBuild, RandomSoupSpheresAndMix) {
  build_and_check(random_soup(5000, 1), {});
  build_and_check({}, random_spheres(3000, 2));
  build_and_check(random_soup(2000, 3), random_spheres(2000, 4));
}

TEST(BvhBuild, ClosedMeshes) {
  build_and_check(lucent::bvh::meshes::icosphere(5).triangles(), {});
  build_and_check(lucent::bvh::meshes::torus(300, 100, 1.0f, 0.3f, 0.2f).triangles(), {});
}

TEST(BvhBuild, LeafSizeOption) {
  auto t = random_soup(3000, 5);
  for (int leaf : {1, 2, 8, 16}) {
    BuildOptions o;
    o.max_leaf_size = leaf;
    build_and_check(t, {}, o);
  }
}

// All centroids equal: binning cannot separate them; leaves must still respect the limit.
TEST(BvhBuild, AllCentroidsEqual) {
  std::vector<lc_triangle> t;
  for (int i = 0; i < 1000; ++i) {
    float s = 1.0f + i * 0.001f;  // nested triangles around the same centroid
    t.push_back(tri(-s, -s, 0, 2 * s, -s, 0, -s, 2 * s, 0));
  }
  build_and_check(t, {});
  std::vector<lc_sphere> sp(500);
  for (auto& s : sp) s = lc_sphere{{1, 2, 3}, 0.5f, 0, LC_INVALID, 0, 0};
  build_and_check(t, sp);
}

// Zero-extent boxes: points, segments and axis-aligned triangles, also all at one point.
TEST(BvhBuild, ZeroExtentBoxes) {
  std::vector<lc_triangle> t;
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> u(0, 1);
  for (int i = 0; i < 500; ++i) {
    float x = u(rng), y = u(rng), z = u(rng);
    t.push_back(tri(x, y, z, x, y, z, x, y, z));                  // a point
    t.push_back(tri(x, y, z, x + 0.01f, y, z, x, y, z));          // a segment
    t.push_back(tri(x, y, z, x + 0.01f, y, z, x, y + 0.01f, z));  // flat in z
  }
  build_and_check(t, {});
  std::vector<lc_triangle> same(100, tri(1, 1, 1, 1, 1, 1, 1, 1, 1));
  build_and_check(same, {});
  std::vector<lc_sphere> dots(100, lc_sphere{{0, 0, 0}, 0.0f, 0, LC_INVALID, 0, 0});
  build_and_check({}, dots);
}

// Exponentially spaced primitives (factor 40 per step, along each axis in turn) make binned SAH
// splits peel off a few primitives per level: the tree stays valid and within the 64 levels of
// the kernel's traversal stack (the builder falls back to median splits near that depth).
TEST(BvhBuild, ExponentialSpacingStaysWithinTheKernelStack) {
  std::vector<lc_triangle> t = lucent::bvh::meshes::exponential_spacing();
  for (int leaf : {1, 4}) {
    BuildOptions o;
    o.max_leaf_size = leaf;
    Bvh b = lucent::bvh::build_binary(t, {}, o);
    check_bvh(b, t, {}, leaf);
    EXPECT_LE(b.stats.max_depth, 64u);
  }
}

// The tree depends only on the input, not on the number of threads.
TEST(BvhBuild, SameTreeWithOneOrTwoThreads) {
  auto t = lucent::bvh::meshes::torus(400, 200, 1.0f, 0.3f, 0.2f).triangles();  // 160k: parallel
  auto s = random_spheres(1000, 7);
  BuildOptions one, two;
  one.threads = 1;
  two.threads = 2;
  Bvh a = lucent::bvh::build_binary(t, s, one), b = lucent::bvh::build_binary(t, s, two);
  check_bvh(b, t, s, 4);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(Node2)));
  EXPECT_EQ(a.prim_refs, b.prim_refs);
}

// SAH quality: on a uniform soup the binned SAH tree costs less than an object-median tree
// built here (same leaf size).
TEST(BvhBuild, SahBeatsMedianSplits) {
  auto t = random_soup(20000, 8, 0.01f);
  BuildOptions o;
  o.leaf_block = 1;  // the classic SAH (cost per primitive), which sah_cost measures
  Bvh b = lucent::bvh::build_binary(t, {}, o);
  check_bvh(b, t, {}, 4);
  // median tree over the same triangles: cost by the same formula
  std::vector<lc_uint> idx(t.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = lc_uint(i);
  std::vector<Node2> med;
  struct Job {
    std::size_t b, e;
  };
  std::vector<Job> jobs{{0, idx.size()}};
  while (!jobs.empty()) {
    Job j = jobs.back();
    jobs.pop_back();
    Node2 nd{};
    for (int a = 0; a < 3; ++a) nd.bmin[a] = INFINITY, nd.bmax[a] = -INFINITY;
    for (std::size_t i = j.b; i < j.e; ++i) {
      double lo[3], hi[3];  // a triangle's box is exact in float
      prim_box(t, {}, idx[i], lo, hi);
      for (int a = 0; a < 3; ++a)
        nd.bmin[a] = std::min(nd.bmin[a], float(lo[a])),
        nd.bmax[a] = std::max(nd.bmax[a], float(hi[a]));
    }
    nd.count = j.e - j.b <= 4 ? lc_uint(j.e - j.b) : 0;
    med.push_back(nd);
    if (nd.count) continue;
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (nd.bmax[a] - nd.bmin[a] > nd.bmax[axis] - nd.bmin[axis]) axis = a;
    std::size_t mid = (j.b + j.e) / 2;
    std::nth_element(idx.begin() + j.b, idx.begin() + mid, idx.begin() + j.e,
                     [&](lc_uint x, lc_uint y) {
                       return t[x].v0[axis] + t[x].v1[axis] + t[x].v2[axis] <
                              t[y].v0[axis] + t[y].v1[axis] + t[y].v2[axis];
                     });
    jobs.push_back({j.b, mid});
    jobs.push_back({mid, j.e});
  }
  double median_cost = lucent::bvh::sah_cost(med);
  EXPECT_LT(b.stats.sah_cost, median_cost);
}

// reorder_triangles: the triangles in leaf order, prim_refs rewritten, spheres untouched, and a
// valid tree over the permuted triangles.
TEST(BvhBuild, ReorderTrianglesIntoLeafOrder) {
  auto t = random_soup(3000, 9);
  auto s = random_spheres(500, 10);
  Bvh b = lucent::bvh::build_binary(t, s);
  std::vector<lc_uint> old_refs = b.prim_refs;
  std::vector<lc_triangle> moved = t;
  std::vector<lc_uint> new_to_old = lucent::bvh::reorder_triangles(b, moved);
  ASSERT_EQ(new_to_old.size(), t.size());
  std::vector<int> seen(t.size(), 0);
  for (std::size_t i = 0; i < moved.size(); ++i) {
    ASSERT_LT(new_to_old[i], t.size());
    ++seen[new_to_old[i]];
    EXPECT_EQ(0, std::memcmp(&moved[i], &t[new_to_old[i]], sizeof(lc_triangle)));
  }
  for (int c : seen) ASSERT_EQ(c, 1);
  lc_uint next = 0;
  for (std::size_t i = 0; i < b.prim_refs.size(); ++i) {
    if (old_refs[i] & LC_PRIM_SPHERE_BIT) {
      EXPECT_EQ(b.prim_refs[i], old_refs[i]);
    } else {
      EXPECT_EQ(b.prim_refs[i], next++);  // leaf order
      EXPECT_EQ(new_to_old[b.prim_refs[i]], old_refs[i]);
    }
  }
  check_bvh(b, moved, s, 4);
}

// The default traversal cost (BuildOptions::traversal_cost, about what a binary step costs in the
// kernel's 8-wide nodes relative to a leaf block) keeps the walls of a box in leaves of their own:
// a leaf holding two walls spans the box's volume, and every ray inside the box entered it. The
// classic cost of 1 filled blocks of 4 with two walls (the Cornell box's rays then entered 2.5
// leaves each, BENCHMARKS.md).
TEST(BvhBuild, BoxWallsGetFlatLeaves) {
  std::vector<lc_triangle> t;
  auto quad = [&](float ax, float ay, float az, float bx, float by, float bz, float cx, float cy,
                  float cz, float dx, float dy, float dz) {
    t.push_back(tri(ax, ay, az, bx, by, bz, cx, cy, cz));
    t.push_back(tri(ax, ay, az, cx, cy, cz, dx, dy, dz));
  };
  quad(-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1);    // floor
  quad(-1, 2, -1, 1, 2, -1, 1, 2, 1, -1, 2, 1);    // ceiling
  quad(-1, 0, -1, 1, 0, -1, 1, 2, -1, -1, 2, -1);  // back
  quad(-1, 0, -1, -1, 0, 1, -1, 2, 1, -1, 2, -1);  // left
  quad(1, 0, -1, 1, 0, 1, 1, 2, 1, 1, 2, -1);      // right
  auto flat_leaves = [](const Bvh& b) {
    int flat = 0, leaves = 0;
    for (const Node2& n : b.nodes) {
      if (n.count == 0) continue;  // interior nodes and node 1, the padding
      ++leaves;
      float ext = std::min({n.bmax[0] - n.bmin[0], n.bmax[1] - n.bmin[1], n.bmax[2] - n.bmin[2]});
      flat += ext == 0.0f;
    }
    return std::make_pair(flat, leaves);
  };
  Bvh b = lucent::bvh::build_binary(t, {});
  auto [flat, leaves] = flat_leaves(b);
  EXPECT_EQ(flat, leaves);
  EXPECT_EQ(leaves, 5);
  check_bvh(b, t, {}, 4);
  BuildOptions classic;
  classic.traversal_cost = 1.0f;
  auto [flat1, leaves1] = flat_leaves(lucent::bvh::build_binary(t, {}, classic));
  EXPECT_LT(flat1, leaves1);  // the comparison this test stands on
}

}  // namespace

}  // namespace test_bvh_build
