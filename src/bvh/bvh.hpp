#pragma once
// BVH over all primitives of a scene (triangles and spheres): a binary SAH tree (build_binary),
// collapsed into the wide nodes the kernel walks (lc_bvh_node, kernels/shared/types.h).
#include <cstdint>
#include <vector>

#include "core/host_blocks.hpp"
#include "shared/types.h"

namespace lucent::bvh {

/// A read-only view of the primitives of a std::vector or a sys::HostVector (the packed scene's).
template <class T>
struct Span {
  const T* ptr = nullptr;
  std::size_t n = 0;
  Span() = default;
  template <class A>
  Span(const std::vector<T, A>& v) : ptr(v.data()), n(v.size()) {}  // NOLINT: implicit
  std::size_t size() const { return n; }
  bool empty() const { return n == 0; }
  const T& operator[](std::size_t i) const { return ptr[i]; }
};

struct BuildOptions {
  /// A leaf is forced to split above this many primitives (clamped to 1..LC_BVH_LEAF_MAX).
  int max_leaf_size = 4;
  int threads = 0;  ///< 0: hardware concurrency
  /// SAH cost of one binary traversal step relative to one leaf block's intersection: larger
  /// values give larger leaves and fewer nodes. The kernel walks 8-wide nodes, each about three
  /// binary levels, and one wide node's test costs about one leaf block's (~120 instructions
  /// each, AVX2), so a binary step costs about a fifth to a third of a block. At 1 (the classic
  /// value) leaves always filled their block, and a leaf holding two walls of a box spans the
  /// box's volume: rays inside it entered 2.5 leaves each. 0.2 separates such walls:
  /// traversal instructions -29% on the Cornell box, -17% on the dragon box, unchanged on a bare
  /// mesh, +6% on a scene of spheres on a plane (BENCHMARKS.md, "Throughput against Mitsuba 3").
  float traversal_cost = 0.2f;
  /// Triangles the kernel tests together (lc_bvh_leaf holds 4): the SAH counts a leaf's
  /// intersection cost in blocks of this many triangles, plus one per sphere (spheres are tested
  /// one by one), so leaves fill blocks when that is no worse.
  int leaf_block = 4;
};

struct BuildStats {
  double seconds = 0;  ///< binary build and, for build(), the collapse
  std::size_t primitives = 0;
  std::size_t nodes = 0;  ///< nodes of this tree (wide nodes for build())
  std::size_t leaves = 0;
  std::size_t max_depth = 0;  ///< of this tree (root: 1)
  std::size_t max_leaf_size = 0;
  double mean_leaf_size = 0;
  double sah_cost = 0;  ///< of the binary tree: traversal cost 1, intersection cost 1, / root area
  std::size_t binary_nodes = 0;      ///< nodes of the binary tree it was collapsed from
  std::size_t binary_max_depth = 0;  ///< depth of that binary tree
};

/// Binary tree node, host only (the build's intermediate tree).
struct Node2 {
  float bmin[3];       ///< bounds minimum
  lc_uint left_first;  ///< interior: left child (right = left + 1); leaf: first prim_refs entry
  float bmax[3];       ///< bounds maximum
  lc_uint count;       ///< 0 for an interior node, else the number of primitives in the leaf
};
static_assert(sizeof(Node2) == 32, "Node2 should stay 32 bytes");

/// Binary SAH tree. nodes[0] is the root; nodes[1] is an unused empty box when the root is not a
/// leaf, so that every sibling pair starts at an even index; children of an interior node are
/// adjacent and laid out depth-first.
struct Bvh2 {
  std::vector<Node2> nodes;        ///< empty when there is no primitive
  std::vector<lc_uint> prim_refs;  ///< triangle index, or sphere index | LC_PRIM_SPHERE_BIT
  BuildStats stats;
};

/// The tree the kernel walks: wide nodes and leaf blocks (kernels/shared/types.h), depth-first.
struct Bvh {
  /// nodes[0] is the root; empty when there is no primitive. (Host vectors, as the packed scene's
  /// arrays: pack_scene moves them there.)
  sys::HostVector<lc_bvh_node> nodes;
  /// Leaf blocks, in the order the collapse meets the leaves; they hold the primitive references
  /// (triangle index, or sphere index | LC_PRIM_SPHERE_BIT).
  sys::HostVector<lc_bvh_leaf> leaves;
  float bmin[3] = {0, 0, 0}, bmax[3] = {0, 0, 0};  ///< bounds of the scene (0 when empty)
  BuildStats stats;
};

/// Builds the binary SAH tree over `triangles` then `spheres`.
Bvh2 build_binary(Span<lc_triangle> triangles, Span<lc_sphere> spheres,
                  const BuildOptions& options = {});

/// Collapses a binary tree built over `triangles` (then spheres) into wide nodes: each wide node
/// is made from an interior binary node, opened, and takes as its children (at most LC_BVH_WIDTH)
/// the descendants that give the wide tree the least SAH cost (bvh_wide.cpp). Each leaf becomes
/// 1 to 4 consecutive leaf blocks holding the vertices of its triangles.
Bvh collapse(const Bvh2& binary, Span<lc_triangle> triangles);

/// build_binary, then collapse.
Bvh build(Span<lc_triangle> triangles, Span<lc_sphere> spheres, const BuildOptions& options = {});

/// SAH cost of a binary tree (same convention as BuildStats::sah_cost).
double sah_cost(const std::vector<Node2>& nodes);

}  // namespace lucent::bvh
