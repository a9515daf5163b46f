#pragma once
// The binned SAH builder proper (Wald, "On fast Construction of SAH-based Bounding Volume
// Hierarchies", 2007): 32 bins per axis over the centroid bounds, all three axes, multithreaded
// by handing large subtrees to a small pool of std::threads. build_binary() (bvh_build.cpp)
// prepares the primitive references and flattens the scratch tree it returns.
#include <cstddef>
#include <memory>
#include <vector>

#include "bvh/bvh.hpp"
#include "bvh/bvh_simd.hpp"

namespace lucent::bvh::detail {

/// The scratch tree over `refs` (reordered in place so that every leaf covers a range of them):
/// nodes[0] is the root, the children of an interior node are adjacent, slots are handed out
/// depth-first per subtree (not in a flat order). `box` and `cbox` bound the primitives and their
/// doubled centroids.
struct ScratchTree {
  std::unique_ptr<Node2[]> nodes;
  std::size_t count = 0;      ///< nodes used
  std::size_t max_depth = 0;  ///< root: 1
};
ScratchTree build_sah_tree(std::vector<PrimRef>& refs, const Box& box, const Box& cbox,
                           const BuildOptions& options, unsigned threads, bool has_spheres);

}  // namespace lucent::bvh::detail
