#pragma once
// BVH over all primitives of a scene (triangles and spheres), flattened into lc_bvh_node.
#include <cstdint>
#include <vector>

#include "shared/types.h"

namespace lucent::bvh {

struct BuildOptions {
  int max_leaf_size = 4;  ///< a leaf is forced to split above this many primitives
  int threads = 0;        ///< 0: hardware concurrency
  /// SAH cost of one traversal step relative to one primitive intersection: larger values give
  /// larger leaves and fewer nodes.
  float traversal_cost = 1.0f;
};

struct BuildStats {
  double seconds = 0;
  std::size_t primitives = 0;
  std::size_t nodes = 0;
  std::size_t leaves = 0;
  std::size_t max_depth = 0;
  std::size_t max_leaf_size = 0;
  double mean_leaf_size = 0;
  double sah_cost = 0;  ///< traversal cost 1, intersection cost 1, relative to the root area
};

struct Bvh {
  std::vector<lc_bvh_node> nodes;  ///< nodes[0] is the root; empty when there is no primitive
  std::vector<lc_uint> prim_refs;  ///< triangle index, or sphere index | LC_PRIM_SPHERE_BIT
  BuildStats stats;
};

/// Builds the BVH over `triangles` then `spheres`.
Bvh build(const std::vector<lc_triangle>& triangles, const std::vector<lc_sphere>& spheres,
          const BuildOptions& options = {});

/// Puts the triangles in the order in which the leaves reference them (neighbouring leaves then
/// read neighbouring memory in the kernel) and rewrites bvh.prim_refs to match; spheres are left
/// as they are. Returns, for each new triangle index, its old index: callers permute arrays kept
/// parallel to the triangles with it and remap stored triangle indices (lights).
std::vector<lc_uint> reorder_triangles(Bvh& bvh, std::vector<lc_triangle>& triangles);

/// SAH cost of a built tree (same convention as BuildStats::sah_cost).
double sah_cost(const std::vector<lc_bvh_node>& nodes);

}  // namespace lucent::bvh
