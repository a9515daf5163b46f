// reorder_triangles (reorder.hpp).
#include "support/reorder.hpp"

#include <stdexcept>

namespace lucent::bvh {

namespace {

std::vector<lc_uint> reorder_refs(std::vector<lc_uint>& prim_refs,
                                  std::vector<lc_triangle>& triangles) {
  std::vector<lc_uint> new_to_old;
  new_to_old.reserve(triangles.size());
  for (lc_uint& ref : prim_refs) {
    if (ref & LC_PRIM_SPHERE_BIT) continue;
    new_to_old.push_back(ref);
    ref = static_cast<lc_uint>(new_to_old.size() - 1);
  }
  if (new_to_old.size() != triangles.size())
    throw std::logic_error("reorder_triangles: the BVH was not built over these triangles");
  std::vector<lc_triangle> out(triangles.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = triangles[new_to_old[i]];
  triangles.swap(out);
  return new_to_old;
}

}  // namespace

std::vector<lc_uint> reorder_triangles(Bvh& bvh, std::vector<lc_triangle>& triangles) {
  // the order of the leaf blocks (LC_INVALID has the sphere bit)
  std::vector<lc_uint> refs;
  refs.reserve(4 * bvh.leaves.size());
  for (const lc_bvh_leaf& l : bvh.leaves)
    for (lc_uint ref : l.prim)
      if (ref != LC_INVALID) refs.push_back(ref);
  std::vector<lc_uint> new_to_old = reorder_refs(refs, triangles);
  std::vector<lc_uint> old_to_new(new_to_old.size());
  for (std::size_t i = 0; i < new_to_old.size(); ++i) old_to_new[new_to_old[i]] = lc_uint(i);
  for (lc_bvh_leaf& l : bvh.leaves)
    for (lc_uint& ref : l.prim)
      if (!(ref & LC_PRIM_SPHERE_BIT)) ref = old_to_new[ref];
  return new_to_old;
}

std::vector<lc_uint> reorder_triangles(Bvh2& bvh, std::vector<lc_triangle>& triangles) {
  return reorder_refs(bvh.prim_refs, triangles);
}

}  // namespace lucent::bvh
