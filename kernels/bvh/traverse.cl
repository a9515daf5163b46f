/* lucent kernel: scene description on the device and BVH2 traversal.
 * Node layout: shared/types.h (lc_bvh_node, 32 bytes, depth-first, children adjacent). Leaves
 * hold primitive references: a triangle index, or a sphere index with LC_PRIM_SPHERE_BIT set.
 * Traversal is ordered (nearer child first) with a stack of (node, entry distance) pairs, so a
 * popped node is dropped without touching its box once a closer hit is known. */
#ifndef LUCENT_BVH_TRAVERSE_CL
#define LUCENT_BVH_TRAVERSE_CL

/* Deep enough for any tree of src/bvh/bvh_build.cpp, which caps the depth at 64. */
#define LC_BVH_STACK_SIZE 64

typedef struct {
  __global const lc_params* params;
  __global const lc_bvh_node* nodes;
  __global const lc_uint* prim_refs;
  __global const lc_triangle* triangles;
  __global const lc_triangle_attr* tri_attrs;
  __global const lc_sphere* spheres;
  __global const lc_material* materials;
  __global const lc_light* lights;
  __global const float* light_cdf;
  __global const lc_texture* textures;
  __global const float4* texels;
} lc_scene;

/* The scene's kernel arguments, in the order of src/render/device_scene.cpp (DeviceScene). */
#define LC_SCENE_KERNEL_ARGS                                                                  \
  __global const lc_params *params, __global const lc_bvh_node *nodes,                        \
      __global const lc_uint *prim_refs, __global const lc_triangle *triangles,               \
      __global const lc_triangle_attr *tri_attrs, __global const lc_sphere *spheres,          \
      __global const lc_material *materials, __global const lc_light *lights,                 \
      __global const float *light_cdf, __global const lc_texture *textures,                   \
      __global const float4 *texels

/* The lc_scene of a kernel declared with LC_SCENE_KERNEL_ARGS. */
#define LC_SCENE_FROM_KERNEL_ARGS                                                             \
  {params, nodes, prim_refs, triangles, tri_attrs, spheres, materials, lights, light_cdf,     \
   textures, texels}

typedef struct {
  lc_real t;
  lc_uint prim; /* primitive reference (LC_PRIM_SPHERE_BIT for spheres), LC_INVALID on a miss */
  lc_real b1, b2; /* triangle barycentrics of v1 and v2 */
} lc_hit;

/* 1 / d per component, +INFINITY where d is 0 (either sign) or so small that 1 / d overflows. */
static inline lc_real3 bvh_inv_dir(lc_real3 d) {
  lc_real3 inv = LC_REAL(1.0) / d;
  return select(inv, (lc_real3)(INFINITY), isinf(inv));
}

/*
 * Slab test: the distance at which the ray enters the box within [tmin, tmax], or INFINITY on a
 * miss. With inv_d = +INFINITY on an axis the ray does not move along, (b - o) * inv_d is -inf or
 * +inf, or NaN (0 * inf) when the origin lies on that face plane. The selects below return t0 for
 * the near and t1 for the far distance whenever either is NaN, and the comparisons with enter and
 * exit keep the old value for a NaN: an origin on a face plane of a slab it does not move along
 * counts as inside that slab (boxes are closed), and no NaN decides anything.
 */
static inline lc_real bvh_box_entry(__global const lc_bvh_node* n, lc_real3 o, lc_real3 inv_d,
                                    lc_real tmin, lc_real tmax) {
  lc_real3 t0 = (lc_real3_from_float3(vload3(0, n->bmin)) - o) * inv_d;
  lc_real3 t1 = (lc_real3_from_float3(vload3(0, n->bmax)) - o) * inv_d;
  lc_real3 tn = select(t0, t1, t1 < t0);
  lc_real3 tf = select(t1, t0, t0 > t1);
  lc_real enter = tmin, exit_ = tmax;
  enter = tn.x > enter ? tn.x : enter;
  enter = tn.y > enter ? tn.y : enter;
  enter = tn.z > enter ? tn.z : enter;
  exit_ = tf.x < exit_ ? tf.x : exit_;
  exit_ = tf.y < exit_ ? tf.y : exit_;
  exit_ = tf.z < exit_ ? tf.z : exit_;
  /* conservative against rounding in t0, t1: widen the exit by 1 + 2 gamma(3) (pbrt-v4) */
#ifdef LC_DOUBLE
  exit_ *= 1.0000000000000007; /* the same in double */
#else
  exit_ *= 1.0000004f;
#endif
  return enter <= exit_ ? enter : INFINITY;
}

static inline int bvh_intersect_prim(const lc_scene* s, lc_uint ref, const lc_tri_ray* tr,
                                     lc_real3 o, lc_real3 d, lc_real tmin, lc_hit* hit) {
  if (ref & LC_PRIM_SPHERE_BIT) {
    __global const lc_sphere* sp = &s->spheres[ref & ~LC_PRIM_SPHERE_BIT];
    lc_real t = sphere_intersect(lc_real3_from_float3(vload3(0, sp->center)), sp->radius, o, d,
                                 tmin, hit->t);
    if (t < hit->t) {
      hit->t = t;
      hit->prim = ref;
      return 1;
    }
    return 0;
  }
  __global const lc_triangle* tri = &s->triangles[ref];
  lc_real t, b1, b2;
  if (triangle_intersect(tr, o, lc_real3_from_float3(vload3(0, tri->v0)),
                         lc_real3_from_float3(vload3(0, tri->v1)),
                         lc_real3_from_float3(vload3(0, tri->v2)), tmin,
                         hit->t, &t, &b1, &b2)) {
    hit->t = t;
    hit->prim = ref;
    hit->b1 = b1;
    hit->b2 = b2;
    return 1;
  }
  return 0;
}

/* Closest hit with t in (tmin, tmax). With any_hit set, returns at the first hit found (shadow
 * rays); hit then holds that hit, not necessarily the closest. */
static inline int bvh_trace(const lc_scene* s, lc_real3 o, lc_real3 d, lc_real tmin, lc_real tmax,
                            int any_hit, lc_hit* hit) {
  hit->t = tmax;
  hit->prim = LC_INVALID;
  hit->b1 = hit->b2 = LC_REAL(0.0);
  if (s->params->num_nodes == 0) return 0;
  __global const lc_bvh_node* nodes = s->nodes;
  lc_real3 inv_d = bvh_inv_dir(d);
  if (bvh_box_entry(&nodes[0], o, inv_d, tmin, tmax) == INFINITY) return 0;
  lc_tri_ray tr = triangle_ray_setup(d);
  lc_uint stack_node[LC_BVH_STACK_SIZE];
  lc_real stack_t[LC_BVH_STACK_SIZE];
  int sp = 0;
  lc_uint node = 0;
  for (;;) {
    __global const lc_bvh_node* n = &nodes[node];
    lc_uint count = n->count, first = n->left_first;
    if (count > 0) {
      for (lc_uint i = 0; i < count; ++i)
        if (bvh_intersect_prim(s, s->prim_refs[first + i], &tr, o, d, tmin, hit) && any_hit)
          return 1;
    } else {
      lc_real tl = bvh_box_entry(&nodes[first], o, inv_d, tmin, hit->t);
      lc_real tr_ = bvh_box_entry(&nodes[first + 1], o, inv_d, tmin, hit->t);
      lc_uint near_ = tl <= tr_ ? first : first + 1;
      lc_real t_near = fmin(tl, tr_), t_far = fmax(tl, tr_);
      if (t_near != INFINITY) {
        if (t_far != INFINITY && sp < LC_BVH_STACK_SIZE) {
          stack_node[sp] = (near_ == first) ? first + 1 : first;
          stack_t[sp] = t_far;
          ++sp;
        }
        node = near_;
        continue;
      }
    }
    /* pop the nearest pending node that may still hold a closer hit */
    for (;;) {
      if (sp == 0) return hit->prim != LC_INVALID;
      --sp;
      if (stack_t[sp] < hit->t) break;
    }
    node = stack_node[sp];
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
