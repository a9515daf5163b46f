#pragma once
// Triangles in leaf order, for the BVH tests and the benchmark (the renderer does not reorder:
// src/render/pack.cpp keeps the scene's order).
#include <vector>

#include "bvh/bvh.hpp"

namespace lucent::bvh {

/// Puts the triangles in the order in which the leaves reference them (the leaf blocks' order for
/// a Bvh, prim_refs' for a Bvh2) and rewrites the references (the blocks' or prim_refs) to
/// match, so that shading reads neighbouring memory for neighbouring leaves; spheres are left
/// as they are. Returns, for each new triangle index, its old index: callers permute arrays kept
/// parallel to the triangles with it and remap stored triangle indices (lights).
std::vector<lc_uint> reorder_triangles(Bvh& bvh, std::vector<lc_triangle>& triangles);
std::vector<lc_uint> reorder_triangles(Bvh2& bvh, std::vector<lc_triangle>& triangles);

}  // namespace lucent::bvh
