// Binary SAH BVH (bvh.hpp): primitive bounds, the binned SAH builder (sah_builder.cpp) and the
// scratch tree flattened depth-first with adjacent children (Node2); bvh_wide.cpp collapses it
// into the wide nodes the kernel walks.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "bvh/bvh.hpp"
#include "bvh/sah_builder.hpp"

namespace lucent::bvh {

using detail::Box;
using detail::PrimRef;
using detail::V4;

namespace {

template <class F>
void parallel_for(std::size_t n, unsigned threads, F f) {
  if (threads <= 1 || n < 4096) {
    f(std::size_t(0), n, 0u);
    return;
  }
  std::vector<std::thread> pool;
  std::size_t step = (n + threads - 1) / threads;
  for (unsigned p = 1; p < threads; ++p)
    pool.emplace_back(f, std::min(n, p * step), std::min(n, (p + 1) * step), p);
  f(std::size_t(0), std::min(n, step), 0u);
  for (auto& t : pool) t.join();
}

double node_area(const Node2& n) {
  double d[3];
  for (int a = 0; a < 3; ++a) d[a] = std::max(0.0, double(n.bmax[a]) - n.bmin[a]);
  return 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

double sah_term(const Node2& n, double root) {
  return node_area(n) / root * (n.count ? double(n.count) : 1.0);
}

}  // namespace

double sah_cost(const std::vector<Node2>& nodes) {
  if (nodes.empty()) return 0;
  double root = node_area(nodes[0]);
  if (root <= 0) return 0;
  double cost = 0;
  for (const auto& n : nodes) cost += sah_term(n, root);
  return cost;
}

namespace detail {

ScratchBuild build_scratch(Span<lc_triangle> tris, Span<lc_sphere> spheres,
                           const BuildOptions& options_in, unsigned& threads) {
  ScratchBuild out;
  out.start = std::chrono::steady_clock::now();
  BuildOptions options = options_in;
  options.max_leaf_size = std::min(std::max(options.max_leaf_size, 1), int(LC_BVH_LEAF_MAX));
  const std::size_t nt = tris.size(), n = nt + spheres.size();
  out.stats.primitives = n;
  threads = 1;
  if (n == 0) return out;
  threads = options.threads > 0 ? static_cast<unsigned>(options.threads)
                                : std::max(1u, std::thread::hardware_concurrency());

  // primitive bounds, and the root's bounds and centroid bounds, one slice per thread. A
  // primitive whose bounds are not finite (a NaN sphere, which validate_scene allows: it is never
  // hit) stays out of the tree: growing a box by a NaN bound (SSE min/max return their second
  // operand) dropped the primitives grown before it, which then were never hit either.
  std::vector<PrimRef> refs(n);
  std::vector<char> kept(n, 1);
  std::vector<Box> part_box(threads), part_cbox(threads);
  parallel_for(n, threads, [&](std::size_t b, std::size_t e, unsigned p) {
    Box box, cbox;
    for (std::size_t i = b; i < e; ++i) {
      alignas(16) float lo[4], hi[4];
      lc_uint id;
      if (i < nt) {
        const lc_triangle& t = tris[i];
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(t.v0[a], std::min(t.v1[a], t.v2[a]));
          hi[a] = std::max(t.v0[a], std::max(t.v1[a], t.v2[a]));
        }
        id = static_cast<lc_uint>(i);
      } else {
        const lc_sphere& s = spheres[i - nt];
        // centre -+ radius rounded outward: to the nearest float, a face of the box could fall
        // inside the sphere, and rays grazing it were culled (5% of the radius at 1e6)
        const double rad = std::fabs(double(s.radius));
        for (int a = 0; a < 3; ++a) {
          const double l = double(s.center[a]) - rad, h = double(s.center[a]) + rad;
          lo[a] = static_cast<float>(l);
          hi[a] = static_cast<float>(h);
          if (double(lo[a]) > l) lo[a] = std::nextafter(lo[a], -INFINITY);
          if (double(hi[a]) < h) hi[a] = std::nextafter(hi[a], INFINITY);
        }
        id = static_cast<lc_uint>(i - nt) | LC_PRIM_SPHERE_BIT;
      }
      std::memcpy(&lo[3], &id, sizeof id);
      hi[3] = 0;
      PrimRef& r = refs[i];
      r.lo = V4::load(lo);
      r.hi = V4::load(hi);
      bool finite = true;
      for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(lo[a]) && std::isfinite(hi[a]);
      if (!finite) {
        kept[i] = 0;
        continue;
      }
      box.grow(r.lo, r.hi);
      cbox.grow_point(r.centroid2());
    }
    part_box[p] = box;
    part_cbox[p] = cbox;
  });
  Box box, cbox;
  for (unsigned p = 0; p < threads; ++p) {
    box.grow(part_box[p]);
    cbox.grow(part_cbox[p]);
  }
  if (std::find(kept.begin(), kept.end(), 0) != kept.end()) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (kept[i]) refs[k++] = refs[i];
    refs.resize(k);
    if (k == 0) return out;
  }
  std::vector<char>().swap(kept);

  out.tree = build_sah_tree(refs, box, cbox, options, threads, !spheres.empty());
  // the references' order is all that is left of them (32 bytes a primitive: gone before the
  // tree is flattened or collapsed)
  out.prim_refs.resize(refs.size());
  parallel_for(refs.size(), threads, [&](std::size_t b, std::size_t e, unsigned) {
    for (std::size_t i = b; i < e; ++i) out.prim_refs[i] = refs[i].id();
  });
  std::vector<PrimRef>().swap(refs);
  out.stats.nodes = out.tree.count;
  out.stats.max_depth = out.tree.max_depth;
  return out;
}

double scratch_sah_cost(const Node2* nodes) {
  const double root = node_area(nodes[0]);
  if (root <= 0) return 0;
  // the root, then each interior node's children in the order the depth-first copy places them
  // (its padding node adds 0)
  double cost = sah_term(nodes[0], root);
  std::vector<lc_uint> stack{0};
  while (!stack.empty()) {
    const Node2& s = nodes[stack.back()];
    stack.pop_back();
    if (s.count != 0) continue;
    cost += sah_term(nodes[s.left_first], root);
    cost += sah_term(nodes[s.left_first + 1], root);
    stack.push_back(s.left_first + 1);
    stack.push_back(s.left_first);
  }
  return cost;
}

}  // namespace detail

Bvh2 build_binary(Span<lc_triangle> tris, Span<lc_sphere> spheres, const BuildOptions& options) {
  unsigned threads = 1;
  detail::ScratchBuild sb = detail::build_scratch(tris, spheres, options, threads);
  Bvh2 out;
  out.stats = sb.stats;
  if (sb.tree.count == 0) return out;
  const std::size_t count = sb.tree.count;
  const Node2* tmp = sb.tree.nodes.get();

  // flatten depth-first: a node's children are adjacent and its left subtree follows them. Node 1
  // is padding (an empty box, never referenced) so that every sibling pair starts at an even
  // index: with a 64-byte aligned buffer, the two boxes a traversal step tests share one cache
  // line.
  const lc_uint first_pair = count > 1 ? 2 : 1;
  out.nodes.resize(count + (first_pair - 1));
  if (count > 1) {
    Node2& pad = out.nodes[1];
    for (int a = 0; a < 3; ++a) pad.bmin[a] = INFINITY, pad.bmax[a] = -INFINITY;
    pad.left_first = 0;
    pad.count = 0;
  }
  out.prim_refs = std::move(sb.prim_refs);
  struct Item {
    lc_uint src, dst;
  };
  std::vector<Item> stack{{0, 0}};
  lc_uint next = first_pair;
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    const Node2& s = tmp[it.src];
    Node2& d = out.nodes[it.dst];
    d = s;
    if (s.count == 0) {
      d.left_first = next;
      next += 2;
      stack.push_back({s.left_first + 1, d.left_first + 1});
      stack.push_back({s.left_first, d.left_first});
    }
  }

  BuildStats& st = out.stats;  // nodes: the padding node left out
  for (const auto& nd : out.nodes)
    if (nd.count) {
      ++st.leaves;
      st.max_leaf_size = std::max<std::size_t>(st.max_leaf_size, nd.count);
    }
  st.mean_leaf_size = double(out.prim_refs.size()) / double(st.leaves);
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - sb.start).count();
  st.sah_cost = sah_cost(out.nodes);  // not part of the build time
  st.binary_nodes = st.nodes;
  st.binary_max_depth = st.max_depth;
  return out;
}

// The scratch tree collapsed directly: its depth-first copy (build_binary's) would sit beside it,
// and the binary tree beside the whole wide tree; the collapse hands back the scratch tree's
// pages as it leaves them behind. The wide tree is the same as collapse(build_binary(...)).
Bvh build(Span<lc_triangle> triangles, Span<lc_sphere> spheres, const BuildOptions& options) {
  unsigned threads = 1;
  detail::ScratchBuild sb = detail::build_scratch(triangles, spheres, options, threads);
  if (sb.tree.count == 0) {
    Bvh2 empty;
    empty.stats = sb.stats;
    empty.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - sb.start).count();
    return collapse(empty, triangles);
  }
  const double binary_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - sb.start).count();
  BuildStats st = sb.stats;
  st.sah_cost = detail::scratch_sah_cost(sb.tree.nodes.get());  // not part of the build time
  const auto t_sah = std::chrono::steady_clock::now();
  st.binary_nodes = st.nodes;
  st.binary_max_depth = st.max_depth;
  // slots: the scratch tree's node indices stay below 2n - 1
  const std::size_t flat_size = st.nodes + (st.nodes > 1 ? 1 : 0);  // with its padding node
  Bvh out = detail::collapse_nodes(sb.tree.nodes.get(), 2 * sb.prim_refs.size() - 1, flat_size,
                                   sb.prim_refs, st, triangles, &sb.tree.nodes);
  out.stats.seconds =
      binary_seconds +
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_sah).count();
  return out;
}

}  // namespace lucent::bvh
