#pragma once
// The binned SAH builder proper (Wald, "On fast Construction of SAH-based Bounding Volume
// Hierarchies", 2007): 32 bins per axis over the centroid bounds, all three axes, multithreaded
// by handing large subtrees to a small pool of std::threads. build_binary() (bvh_build.cpp)
// prepares the primitive references and flattens the scratch tree it returns.
#include <chrono>
#include <cstddef>
#include <memory>
#include <vector>

#include "bvh/bvh.hpp"
#include "bvh/bvh_simd.hpp"

namespace lucent::bvh::detail {

/// Uninitialised storage for the scratch tree's nodes, whose pages can go back to the system
/// while it is read: build() collapses the scratch tree directly (no depth-first copy) and hands
/// back the pages below the nodes it still has to read, so that the binary tree does not sit
/// beside the whole wide tree (a 10^6-triangle soup: 64 bytes a primitive). Anonymous memory on
/// POSIX systems (pages untouched until written), operator new elsewhere (then nothing goes back
/// before the end).
class ScratchNodes {
 public:
  ScratchNodes() = default;
  explicit ScratchNodes(std::size_t n);
  ~ScratchNodes();
  ScratchNodes(ScratchNodes&& o) noexcept;
  ScratchNodes& operator=(ScratchNodes&& o) noexcept;
  ScratchNodes(const ScratchNodes&) = delete;
  ScratchNodes& operator=(const ScratchNodes&) = delete;
  Node2* get() const { return p_; }
  Node2& operator[](std::size_t i) const { return p_[i]; }
  /// The whole pages below node `i` go back to the system (their nodes must not be read again).
  void release_below(std::size_t i);

 private:
  void free_all();
  Node2* p_ = nullptr;
  std::size_t bytes_ = 0;
  std::size_t released_ = 0;  // bytes from the start handed back
  bool mapped_ = false;
};

/// The scratch tree over `refs` (reordered in place so that every leaf covers a range of them):
/// nodes[0] is the root, the children of an interior node are adjacent, slots are handed out
/// depth-first per subtree (not in a flat order). `box` and `cbox` bound the primitives and their
/// doubled centroids.
struct ScratchTree {
  ScratchNodes nodes;
  std::size_t count = 0;      ///< nodes used
  std::size_t max_depth = 0;  ///< root: 1
};
/// The references and scratch tree of a build (bvh_build.cpp): build_binary flattens the tree,
/// build collapses it directly. prim_refs: the primitive references in the tree's order.
struct ScratchBuild {
  ScratchTree tree;
  std::vector<lc_uint> prim_refs;
  BuildStats stats;  ///< primitives, and from the tree nodes (count) and max_depth
  std::chrono::steady_clock::time_point start;
};
ScratchBuild build_scratch(Span<lc_triangle> triangles, Span<lc_sphere> spheres,
                           const BuildOptions& options, unsigned& threads);

/// SAH cost of the scratch tree, summed in the order of its depth-first copy (build_binary's):
/// the same double as sah_cost of that copy.
double scratch_sah_cost(const Node2* nodes);

/// collapse (bvh_wide.cpp) of a binary tree whose root is nodes[0], children adjacent and after
/// their parent (the depth-first copy or the scratch tree; slots: its size, 0 when empty;
/// flat_size: the depth-first copy's). `release`: the scratch storage of `nodes`, whose pages go
/// back as the collapse leaves them behind, or null.
Bvh collapse_nodes(const Node2* nodes, std::size_t slots, std::size_t flat_size,
                   const std::vector<lc_uint>& prim_refs, const BuildStats& stats,
                   Span<lc_triangle> triangles, ScratchNodes* release);

ScratchTree build_sah_tree(std::vector<PrimRef>& refs, const Box& box, const Box& cbox,
                           const BuildOptions& options, unsigned threads, bool has_spheres);

}  // namespace lucent::bvh::detail
