/* lucent kernel: scene description on the device and wide-BVH traversal.
 * Layout: shared/types.h (lc_bvh_node: LC_BVH_WIDTH child boxes as structure of arrays and child
 * references; lc_bvh_leaf: blocks of 4 primitives with their triangles' vertices; built by
 * src/bvh/bvh_wide.cpp). A primitive reference is a triangle index, or a sphere index with
 * LC_PRIM_SPHERE_BIT set.
 * Traversal: one vector operation per slab plane tests all children of a node; the children
 * entered become 32-bit (entry distance, child slot) keys, sorted by a sorting network, the nearest
 * is visited next and the others are pushed farthest first with one vector store (beside their
 * parent's index), so a popped child is dropped without touching a node once a closer hit is
 * known. The triangles of a leaf block are tested at once. Ray quantities are lc_real (float, or
 * double under LC_DOUBLE); boxes and vertices are loaded from the float buffers and widened. The
 * hit record (lc_hit) is in geom/interaction.cl, the scene (lc_scene) in scene/scene.cl. */
#ifndef LUCENT_BVH_TRAVERSE_CL
#define LUCENT_BVH_TRAVERSE_CL

/* At a node of depth k (root: 1) the stack holds at most (LC_BVH_WIDTH - 1) (k - 1) entries and a
 * push writes LC_BVH_WIDTH slots from there; src/bvh keeps the depth within LC_BVH_MAX_DEPTH. */
#define LC_BVH_STACK_SIZE ((LC_BVH_WIDTH - 1) * LC_BVH_MAX_DEPTH + 1)

/* One lane per child. lc_bvh_fw: float per child (a row of lc_bvh_node.bounds); lc_bvh_rw:
 * lc_real per child; lc_bvh_iw, lc_bvh_uw: int, uint per child (stack keys, parent node indices).
 */
#if LC_BVH_WIDTH == 4
typedef float4 lc_bvh_fw;
typedef int4 lc_bvh_iw;
typedef uint4 lc_bvh_uw;
#define lc_bvh_vstorew vstore4
#define lc_bvh_sum(v) ((v).s0 + (v).s1 + (v).s2 + (v).s3)
#define lc_bvh_as_iw as_int4
#define LC_BVH_SLOTS ((int4)(0, 1, 2, 3))
#ifdef LC_DOUBLE
typedef double4 lc_bvh_rw;
#define lc_bvh_rw_from_float(v) convert_double4(v)
#define lc_bvh_float_down(v) convert_float4_rtn(v) /* never above v: culling stays safe */
#define lc_bvh_int_mask(m) convert_int4(m)
#else
typedef float4 lc_bvh_rw;
#define lc_bvh_rw_from_float(v) (v)
#define lc_bvh_float_down(v) (v)
#define lc_bvh_int_mask(m) (m)
#endif
/* Sorting network for 4 keys, descending: (0,1)(2,3), (0,2)(1,3), (1,2). */
static inline lc_bvh_iw bvh_sort_desc(lc_bvh_iw k) {
  lc_bvh_iw p = k.s1032, lo = min(k, p), hi = max(k, p);
  k = (lc_bvh_iw)(hi.s0, lo.s1, hi.s2, lo.s3);
  p = k.s2301;
  lo = min(k, p);
  hi = max(k, p);
  k = (lc_bvh_iw)(hi.s0, hi.s1, lo.s2, lo.s3);
  p = k.s0213;
  lo = min(k, p);
  hi = max(k, p);
  return (lc_bvh_iw)(hi.s0, hi.s1, lo.s2, lo.s3);
}
static inline int bvh_min_key(lc_bvh_iw k) {
  k = min(k, k.s2301);
  k = min(k, k.s1032);
  return k.s0;
}
#elif LC_BVH_WIDTH == 8
typedef float8 lc_bvh_fw;
typedef int8 lc_bvh_iw;
typedef uint8 lc_bvh_uw;
#define lc_bvh_vstorew vstore8
/* the sum of the lanes as a tree of vector additions (a chain of lane extracts measured 16
 * instructions on AVX2, the tree 6) */
static inline int lc_bvh_sum(int8 v) {
  int4 h = v.lo + v.hi;
  h += h.s2301;
  h += h.s1032;
  return h.s0;
}
#define lc_bvh_as_iw as_int8
#define LC_BVH_SLOTS ((int8)(0, 1, 2, 3, 4, 5, 6, 7))
#ifdef LC_DOUBLE
typedef double8 lc_bvh_rw;
#define lc_bvh_rw_from_float(v) convert_double8(v)
#define lc_bvh_float_down(v) convert_float8_rtn(v) /* never above v: culling stays safe */
#define lc_bvh_int_mask(m) convert_int8(m)
#else
typedef float8 lc_bvh_rw;
#define lc_bvh_rw_from_float(v) (v)
#define lc_bvh_float_down(v) (v)
#define lc_bvh_int_mask(m) (m)
#endif
/* Bitonic sorting network for 8 keys, descending: six layers, each lane taking the larger (H) or
 * smaller (L) of itself and its partner. */
#define LC_BVH_LAYER(sw, l0, l1, l2, l3, l4, l5, l6, l7) \
  p = k.sw;                                              \
  lo = min(k, p);                                        \
  hi = max(k, p);                                        \
  k = (lc_bvh_iw)(l0.s0, l1.s1, l2.s2, l3.s3, l4.s4, l5.s5, l6.s6, l7.s7);
static inline lc_bvh_iw bvh_sort_desc(lc_bvh_iw k) {
  lc_bvh_iw p, lo, hi;
  LC_BVH_LAYER(s10325476, hi, lo, lo, hi, hi, lo, lo, hi)
  LC_BVH_LAYER(s23016745, hi, hi, lo, lo, lo, lo, hi, hi)
  LC_BVH_LAYER(s10325476, hi, lo, hi, lo, lo, hi, lo, hi)
  LC_BVH_LAYER(s45670123, hi, hi, hi, hi, lo, lo, lo, lo)
  LC_BVH_LAYER(s23016745, hi, hi, lo, lo, hi, hi, lo, lo)
  LC_BVH_LAYER(s10325476, hi, lo, hi, lo, hi, lo, hi, lo)
  return k;
}
#undef LC_BVH_LAYER
static inline int bvh_min_key(lc_bvh_iw k) {
  int4 h = min(k.lo, k.hi);
  h = min(h, h.s2301);
  h = min(h, h.s1032);
  return h.s0;
}
#else
#error "kernels/bvh/traverse.cl: LC_BVH_WIDTH must be 4 or 8"
#endif

/*
 * Reductions of masks (lanes -1 or 0): bvh_any4, whether a lane of an int4 is set; bvh_count, how
 * many lanes of a node's mask are; bvh_bits4, the lanes as bits (a leaf block's nearest hit). On
 * PoCL's CPU device for x86-64 (LC_DEVICE_POCL_CPU, which the host adds:
 * render_detail::device_defines) they gather the lanes' sign bits with movmskps and count them with
 * popcnt, 2 instructions each, where LLVM compiles the portable forms below lane by lane (any of 4:
 * three shuffles, three ORs, a move and a test; the count of 8: a tree of additions): bvh_trace
 * runs 6% fewer instructions (BENCHMARKS.md, "Mask reductions"). Elsewhere (GPUs, other CPU
 * runtimes) the portable forms: one tree of ORs, which PoCL's any() (two halves, each with its own
 * branch) is not, and a tree of additions. With AVX, bvh_lane_var also takes the nearest hit's
 * lane of a leaf block's barycentrics by one vpermilps, where bvh_lane's chain of selects compiled
 * to branches on the lane that random rays mispredict.
 */
#if defined(LC_DEVICE_POCL_CPU) && defined(__x86_64__) && defined(__has_builtin)
#if __has_builtin(__builtin_ia32_movmskps)
#define LC_BVH_MOVMSK 1
#endif
#endif
#ifdef LC_BVH_MOVMSK
typedef float lc_bvh_m128 __attribute__((__vector_size__(16)));
static inline int bvh_bits4(int4 m) { return __builtin_ia32_movmskps((lc_bvh_m128)as_float4(m)); }
static inline int bvh_any4(int4 m) { return bvh_bits4(m) != 0; }
#if LC_BVH_WIDTH == 8 && defined(__AVX__) && __has_builtin(__builtin_ia32_movmskps256)
typedef float lc_bvh_m256 __attribute__((__vector_size__(32)));
static inline int bvh_count(int8 m) {
  return popcount(__builtin_ia32_movmskps256((lc_bvh_m256)as_float8(m)));
}
#elif LC_BVH_WIDTH == 8
static inline int bvh_count(int8 m) { return popcount(bvh_bits4(m.lo) | (bvh_bits4(m.hi) << 4)); }
#else
static inline int bvh_count(int4 m) { return popcount(bvh_bits4(m)); }
#endif
#if defined(__AVX__) && __has_builtin(__builtin_ia32_vpermilvarps)
#define LC_BVH_VPERMILVAR 1
typedef int lc_bvh_v4si __attribute__((__vector_size__(16)));
static inline float bvh_lane_var(float4 v, int k) {
  return __builtin_ia32_vpermilvarps((lc_bvh_m128)v, (lc_bvh_v4si)(k, k, k, k))[0];
}
#endif
#else
static inline int bvh_any4(int4 m) { return ((m.s0 | m.s1) | (m.s2 | m.s3)) < 0; }
static inline int bvh_count(lc_bvh_iw m) { return -lc_bvh_sum(m); }
#endif

/* leaf blocks: 4 lanes of lc_real */
#ifdef LC_DOUBLE
#define lc_bvh_r4(v) convert_double4(v)
#else
#define lc_bvh_r4(v) (v)
#endif

/* 1 / d per component, +INFINITY where d is 0 (either sign) or so small that 1 / d overflows. */
static inline lc_real3 bvh_inv_dir(lc_real3 d) {
  lc_real3 inv = LC_REAL(1.0) / d;
  return select(inv, (lc_real3)(INFINITY), isinf(inv));
}

static inline lc_real bvh_lane(lc_real4 v, int k) {
  return k == 0 ? v.s0 : (k == 1 ? v.s1 : (k == 2 ? v.s2 : v.s3));
}

/* 1 + 2 gamma(3) of the precision: widens a box's exit distance against rounding (pbrt-v4) */
#ifdef LC_DOUBLE
#define LC_BVH_EXIT_WIDEN 1.0000000000000007
#else
#define LC_BVH_EXIT_WIDEN 1.0000004f
#endif

/* lc_real4 comparison results as int4 and back */
#ifdef LC_DOUBLE
#define lc_bvh_m4(m) convert_int4(m)
#define lc_bvh_rm4(m) convert_long4(m)
#else
#define lc_bvh_m4(m) (m)
#define lc_bvh_rm4(m) (m)
#endif
#if defined(cl_khr_fp64) && !defined(LC_DOUBLE)
#define LC_BVH_FP64_FALLBACK 1
#endif

/*
 * The triangles of one leaf block, all four at once: the watertight test of geom/triangle.cl
 * (Woop, Benthin and Wald 2013) lane by lane, with the same shear (r: triangle_ray_setup; okx,
 * oky, okz: the origin's components along r->kx, r->ky, r->kz), the same operations in the same
 * order without fused multiply-add, and the same fp64 recomputation of a triangle's edge
 * functions when one of them rounds to 0, so each lane decides exactly as triangle_intersect
 * would. Keeps the nearest hit with t in (tmin, hit->t); returns 1 when it found one.
 */
static inline int bvh_leaf_triangles(__global const lc_bvh_leaf* lf, int4 tri, const lc_tri_ray* r,
                                     lc_real okx, lc_real oky, lc_real okz, lc_real tmin,
                                     lc_hit* hit) {
#pragma OPENCL FP_CONTRACT OFF
  __global const float4* v = (__global const float4*)lf->v; /* one row per float4 */
  lc_real4 Az = lc_bvh_r4(v[r->kz]) - okz;
  lc_real4 Bz = lc_bvh_r4(v[3 + r->kz]) - okz;
  lc_real4 Cz = lc_bvh_r4(v[6 + r->kz]) - okz;
  lc_real4 Ax = (lc_bvh_r4(v[r->kx]) - okx) - r->sx * Az;
  lc_real4 Ay = (lc_bvh_r4(v[r->ky]) - oky) - r->sy * Az;
  lc_real4 Bx = (lc_bvh_r4(v[3 + r->kx]) - okx) - r->sx * Bz;
  lc_real4 By = (lc_bvh_r4(v[3 + r->ky]) - oky) - r->sy * Bz;
  lc_real4 Cx = (lc_bvh_r4(v[6 + r->kx]) - okx) - r->sx * Cz;
  lc_real4 Cy = (lc_bvh_r4(v[6 + r->ky]) - oky) - r->sy * Cz;
  lc_real4 U = Cx * By - Cy * Bx;
  lc_real4 V = Ax * Cy - Ay * Cx;
  lc_real4 W = Bx * Ay - By * Ax;
#ifdef LC_BVH_FP64_FALLBACK
  int4 zero = tri & ((U == 0.0f) | (V == 0.0f) | (W == 0.0f));
  if (bvh_any4(zero)) {
    double4 ax = convert_double4(Ax), ay = convert_double4(Ay), bx = convert_double4(Bx);
    double4 by = convert_double4(By), cx = convert_double4(Cx), cy = convert_double4(Cy);
    U = select(U, convert_float4(cx * by - cy * bx), zero);
    V = select(V, convert_float4(ax * cy - ay * cx), zero);
    W = select(W, convert_float4(bx * ay - by * ax), zero);
  }
#endif
  const lc_real z = LC_REAL(0.0);
  int4 ok = tri & ~lc_bvh_m4(((U < z) | (V < z) | (W < z)) & ((U > z) | (V > z) | (W > z)));
  lc_real4 det = U + V + W;
  ok &= lc_bvh_m4(det != z);
  if (!bvh_any4(ok)) return 0;
  lc_real4 T = U * (r->sz * Az) + V * (r->sz * Bz) + W * (r->sz * Cz);
  lc_real4 inv = LC_REAL(1.0) / det;
  lc_real4 t = T * inv;
  ok &= lc_bvh_m4((t > tmin) & (t < hit->t));
  if (!bvh_any4(ok)) return 0;
  lc_real4 tt = select((lc_real4)(INFINITY), t, lc_bvh_rm4(ok));
#if defined(LC_BVH_MOVMSK) && !defined(LC_DOUBLE)
  /* the nearest and its first lane: a tree of minimums and one bit scan */
  float4 mv = min(tt, tt.s1032);
  mv = min(mv, mv.s2301);
  lc_real m = mv.s0;
  int k = __builtin_ctz(bvh_bits4(tt == mv));
#else
  lc_real a = tt.s0 < tt.s1 ? tt.s0 : tt.s1, c = tt.s2 < tt.s3 ? tt.s2 : tt.s3;
  lc_real m = a < c ? a : c;
  int k = tt.s0 == m ? 0 : (tt.s1 == m ? 1 : (tt.s2 == m ? 2 : 3));
#endif
  hit->t = m;
  hit->prim = lf->prim[k];
#if defined(LC_BVH_VPERMILVAR) && !defined(LC_DOUBLE)
  /* lane k of the products (the same bits as the products of lane k) */
  hit->b1 = bvh_lane_var(V * inv, k);
  hit->b2 = bvh_lane_var(W * inv, k);
#else
  hit->b1 = bvh_lane(V, k) * bvh_lane(inv, k);
  hit->b2 = bvh_lane(W, k) * bvh_lane(inv, k);
#endif
  return 1;
}

static inline int bvh_intersect_sphere(const lc_scene* s, lc_uint ref, lc_real3 o, lc_real3 d,
                                       lc_real tmin, lc_hit* hit) {
  __global const lc_sphere* sp = &s->spheres[ref & ~LC_PRIM_SPHERE_BIT];
  lc_real t = sphere_intersect(lc_load3r(sp->center), (lc_real)sp->radius, o, d, tmin, hit->t);
  if (t < hit->t) {
    hit->t = t;
    hit->prim = ref;
    return 1;
  }
  return 0;
}

/* The primitive types to test: the feature defines of the megakernel (src/render/pack.cpp) name
 * those a scene has; a kernel built without them tests both. */
#if defined(LC_HAS_TRIANGLES) || !defined(LC_HAS_SPHERES)
#define LC_BVH_TRIANGLES 1
#endif
#if defined(LC_HAS_SPHERES) || !defined(LC_HAS_TRIANGLES)
#define LC_BVH_SPHERES 1
#endif

/*
 * Closest hit with t in (tmin, tmax). With any_hit set, returns at the first hit found (shadow
 * rays); hit then holds that hit, not necessarily the closest.
 *
 * Slab test per child, all children at once: for each axis the plane the ray meets first (min
 * for a direction >= 0, else max; inv_d is +INFINITY for a zero direction, so min) gives the near
 * distance (b - o) * inv_d, the other plane the far one. The entry is the largest of tmin and the
 * near distances, the exit the smallest of the closest hit so far and the far distances, each
 * taken with `x > acc ? x : acc`, which keeps acc when x is NaN: (b - o) * inv_d is NaN (0 * inf)
 * only for an origin on a face plane of a slab the ray does not move along, and such an origin
 * counts as inside the slab (boxes are closed); no NaN decides anything. An empty slot (min +inf,
 * max -inf) gives near +inf and far -inf and is never entered. The exit is widened by
 * 1 + 2 gamma(3) (pbrt-v4) against rounding in the distances.
 */
static inline int bvh_trace(const lc_scene* s, lc_real3 o, lc_real3 d, lc_real tmin, lc_real tmax,
                            int any_hit, lc_hit* hit) {
  hit->t = tmax;
  hit->prim = LC_INVALID;
  hit->b1 = hit->b2 = LC_REAL(0.0);
  /* a non-finite origin or direction (a scene's NaN, or one computed from degenerate input)
   * would enter every child, the empty slots too, and walk off the node array: such a ray hits
   * nothing (a miss: the integrator adds what a miss adds, the environment's radiance).
   * (o - o) + (d - d) is 0 where finite and NaN where a component is infinite or NaN: its sum
   * decides in 6 instructions what isfinite() of the six components took 20 for. */
  lc_real3 fin = (o - o) + (d - d);
  if (s->params->num_nodes == 0 || !(fin.x + fin.y + fin.z == LC_REAL(0.0))) return 0;
  __global const lc_bvh_node* nodes = s->nodes;
  lc_real3 inv_d = bvh_inv_dir(d);
  /* rows of lc_bvh_node.bounds holding each axis's near plane; the far plane is the next row */
  /* (0, 2, 4) minus the comparisons' -1 where the direction is negative: 6 vector instructions
   * where three scalar selects took 17 */
#ifdef LC_DOUBLE
  const int3 rows = (int3)(0, 2, 4) - convert_int3(inv_d < LC_REAL(0.0));
#else
  const int3 rows = (int3)(0, 2, 4) - (inv_d < LC_REAL(0.0));
#endif
  const int nx = rows.x, ny = rows.y, nz = rows.z;
  lc_tri_ray tr = triangle_ray_setup(d);
  const lc_real4 ok = lc_tri_lanes(o, tr.kx, tr.ky, tr.kz);
  const lc_real okx = ok.x, oky = ok.y, okz = ok.z;
  /* pending children: their keys (entry distance rounded down, slot in the parent; see below)
   * and their parents' node indices */
  int stack_t[LC_BVH_STACK_SIZE];
  lc_uint stack_node[LC_BVH_STACK_SIZE];
  int sp = 0;
  lc_uint ref = 0; /* the root node */
  for (;;) {
    if (!(ref & LC_BVH_LEAF_BIT)) {
      __global const lc_bvh_node* n = &nodes[ref];
      __global const lc_bvh_fw* b = (__global const lc_bvh_fw*)n->bounds; /* rows */
      lc_bvh_rw tnx = (lc_bvh_rw_from_float(b[nx]) - o.x) * inv_d.x;
      lc_bvh_rw tfx = (lc_bvh_rw_from_float(b[nx ^ 1]) - o.x) * inv_d.x;
      lc_bvh_rw tny = (lc_bvh_rw_from_float(b[ny]) - o.y) * inv_d.y;
      lc_bvh_rw tfy = (lc_bvh_rw_from_float(b[ny ^ 1]) - o.y) * inv_d.y;
      lc_bvh_rw tnz = (lc_bvh_rw_from_float(b[nz]) - o.z) * inv_d.z;
      lc_bvh_rw tfz = (lc_bvh_rw_from_float(b[nz ^ 1]) - o.z) * inv_d.z;
      lc_bvh_rw enter = (lc_bvh_rw)(tmin), exit_ = (lc_bvh_rw)(hit->t);
      enter = select(enter, tnx, tnx > enter);
      enter = select(enter, tny, tny > enter);
      enter = select(enter, tnz, tnz > enter);
      exit_ = select(exit_, tfx, tfx < exit_);
      exit_ = select(exit_, tfy, tfy < exit_);
      exit_ = select(exit_, tfz, tfz < exit_);
      exit_ *= LC_BVH_EXIT_WIDEN;
      lc_bvh_rw t = select((lc_bvh_rw)(INFINITY), enter, enter <= exit_);
      lc_bvh_iw hm = lc_bvh_int_mask(t < (lc_bvh_rw)(INFINITY)); /* -1: child entered */
      int cnt = bvh_count(hm);
      if (cnt > 0) {
        /* keys: the entry distance's float bits (t >= 0, so their signed order is the
         * distances'), rounded down to a multiple of 8 ulps, with the child's slot in the three
         * low bits: 32-bit lanes, so the sort is one register's min and max on AVX2 as well as
         * AVX-512. Sorted farthest first, the children missed (INT_MIN) last, the keys are
         * stored whole, each beside this node's index: the first cnt - 1 become the stack's top
         * (second nearest on top); the nearest (smallest key) is visited next. */
        lc_bvh_iw key = (lc_bvh_as_iw(lc_bvh_float_down(t)) & ~7) | LC_BVH_SLOTS;
        int near_ = bvh_min_key(select((lc_bvh_iw)(INT_MAX), key, hm));
        key = bvh_sort_desc(select((lc_bvh_iw)(INT_MIN), key, hm));
        lc_bvh_vstorew(key, 0, &stack_t[sp]);
        lc_bvh_vstorew((lc_bvh_uw)(ref), 0, &stack_node[sp]);
        sp += cnt - 1;
        ref = n->child[near_ & 7];
        continue;
      }
    } else {
      __global const lc_bvh_leaf* lf = &s->leaves[ref & LC_BVH_LEAF_FIRST_MASK];
      __global const lc_bvh_leaf* end =
          lf + ((ref & ~LC_BVH_LEAF_BIT) >> LC_BVH_LEAF_COUNT_SHIFT) + 1;
      for (; lf < end; ++lf) {
        uint4 prim = *(__global const uint4*)lf->prim;
        int4 sphere = (prim & LC_PRIM_SPHERE_BIT) != 0;
#ifdef LC_BVH_TRIANGLES
        int4 tri = ~sphere;
#ifndef LC_BVH_SPHERES
        /* every used column is a triangle, and a block has at least one */
        if (bvh_leaf_triangles(lf, tri, &tr, okx, oky, okz, tmin, hit) && any_hit) return 1;
#else
        if (bvh_any4(tri) && bvh_leaf_triangles(lf, tri, &tr, okx, oky, okz, tmin, hit) && any_hit)
          return 1;
#endif
#endif
#ifdef LC_BVH_SPHERES
        /* LC_INVALID (an unused column) has the sphere bit too */
        int4 used_sphere = sphere & (prim != LC_INVALID);
        if (bvh_any4(used_sphere)) {
          lc_uint refs[4] = {prim.s0, prim.s1, prim.s2, prim.s3};
          for (int k = 0; k < 4; ++k)
            if (refs[k] != LC_INVALID && (refs[k] & LC_PRIM_SPHERE_BIT) &&
                bvh_intersect_sphere(s, refs[k], o, d, tmin, hit) && any_hit)
              return 1;
        }
#endif
      }
    }
    /* pop the nearest pending child that may still hold a closer hit */
    int e;
    do {
      if (sp == 0) return hit->prim != LC_INVALID;
      e = stack_t[--sp];
    } while (!(as_float(e & ~7) < hit->t));
    ref = nodes[stack_node[sp]].child[e & 7];
  }
}

static inline int scene_intersect(const lc_scene* s, lc_ray ray, lc_real tmax, lc_hit* hit) {
  return bvh_trace(s, ray.o, ray.d, LC_REAL(0.0), tmax, 0, hit);
}

/* 1 when something blocks the segment from ray.o to ray.o + dist * ray.d. */
static inline int scene_occluded(const lc_scene* s, lc_ray ray, lc_real dist) {
  lc_hit hit;
  return bvh_trace(s, ray.o, ray.d, LC_REAL(0.0), dist, 1, &hit);
}

#endif
