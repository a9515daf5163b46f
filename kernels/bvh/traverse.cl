/* lucent kernel: scene description on the device and BVH2 traversal.
 * Node layout: shared/types.h (lc_bvh_node, 32 bytes). Leaves hold primitive references: a
 * triangle index, or a sphere index with LC_PRIM_SPHERE_BIT set. */
#ifndef LUCENT_BVH_TRAVERSE_CL
#define LUCENT_BVH_TRAVERSE_CL

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

typedef struct {
  float t;
  lc_uint prim; /* primitive reference (LC_PRIM_SPHERE_BIT for spheres), LC_INVALID on a miss */
  float b1, b2; /* triangle barycentrics of v1 and v2 */
} lc_hit;

/*
 * Slab test. inv_d may hold ±INFINITY for axis-parallel rays; (bmin - o) * inv_d is then ±inf
 * or, when the origin lies on the slab plane, 0 * inf = NaN. fmin/fmax return the non-NaN
 * operand, so a NaN never decides the outcome (the ray is treated as inside that slab).
 */
static inline float bvh_box_entry(const __global lc_bvh_node* n, float3 o, float3 inv_d, float tmin,
                                  float tmax) {
  float3 bmin = lc_load3(n->bmin), bmax = lc_load3(n->bmax);
  float3 t0 = (bmin - o) * inv_d;
  float3 t1 = (bmax - o) * inv_d;
  float3 tn = fmin(t0, t1), tf = fmax(t0, t1);
  float enter = fmax(fmax(tn.x, tn.y), fmax(tn.z, tmin));
  float exit_ = fmin(fmin(tf.x, tf.y), fmin(tf.z, tmax));
  /* robust: 1 + 2*gamma(3) widening of the exit distance (pbrt-v4) */
  exit_ *= 1.0000004f;
  return enter <= exit_ ? enter : INFINITY;
}

static inline int bvh_intersect_prim(const lc_scene* s, lc_uint ref, const lc_tri_ray* tr, float3 o,
                                     float3 d, float tmin, lc_hit* hit) {
  if (ref & LC_PRIM_SPHERE_BIT) {
    __global const lc_sphere* sp = &s->spheres[ref & ~LC_PRIM_SPHERE_BIT];
    float t = sphere_intersect(lc_load3(sp->center), sp->radius, o, d, tmin, hit->t);
    if (t < hit->t) {
      hit->t = t;
      hit->prim = ref;
      return 1;
    }
    return 0;
  }
  __global const lc_triangle* tri = &s->triangles[ref];
  float t, b1, b2;
  if (triangle_intersect(tr, o, lc_load3(tri->v0), lc_load3(tri->v1), lc_load3(tri->v2), tmin,
                         hit->t, &t, &b1, &b2)) {
    hit->t = t;
    hit->prim = ref;
    hit->b1 = b1;
    hit->b2 = b2;
    return 1;
  }
  return 0;
}

/* Closest hit in (tmin, tmax). With any_hit set, returns at the first hit (shadow rays). */
static inline int bvh_trace(const lc_scene* s, float3 o, float3 d, float tmin, float tmax,
                            int any_hit, lc_hit* hit) {
  hit->t = tmax;
  hit->prim = LC_INVALID;
  hit->b1 = hit->b2 = 0.0f;
  if (s->params->num_nodes == 0) return 0;
  lc_tri_ray tr = triangle_ray_setup(d);
  float3 inv_d = 1.0f / d;
  lc_uint stack[LC_BVH_STACK_SIZE];
  int sp = 0;
  lc_uint node = 0;
  if (bvh_box_entry(&s->nodes[0], o, inv_d, tmin, hit->t) == INFINITY) return 0;
  for (;;) {
    __global const lc_bvh_node* n = &s->nodes[node];
    if (n->count > 0) {
      for (lc_uint i = 0; i < n->count; ++i) {
        if (bvh_intersect_prim(s, s->prim_refs[n->left_first + i], &tr, o, d, tmin, hit) &&
            any_hit)
          return 1;
      }
    } else {
      lc_uint l = n->left_first, r = l + 1;
      float tl = bvh_box_entry(&s->nodes[l], o, inv_d, tmin, hit->t);
      float trr = bvh_box_entry(&s->nodes[r], o, inv_d, tmin, hit->t);
      if (tl > trr) {
        float tt = tl;
        tl = trr;
        trr = tt;
        lc_uint tn = l;
        l = r;
        r = tn;
      }
      if (tl != INFINITY) {
        if (trr != INFINITY && sp < LC_BVH_STACK_SIZE) stack[sp++] = r;
        node = l;
        continue;
      }
    }
    /* pop, skipping nodes now farther than the closest hit */
    for (;;) {
      if (sp == 0) return hit->prim != LC_INVALID;
      node = stack[--sp];
      if (bvh_box_entry(&s->nodes[node], o, inv_d, tmin, hit->t) != INFINITY) break;
    }
  }
}

static inline int scene_intersect(const lc_scene* s, lc_ray ray, float tmax, lc_hit* hit) {
  return bvh_trace(s, ray.o, ray.d, 0.0f, tmax, 0, hit);
}

/* 1 when something blocks the segment from ray.o to ray.o + dist * ray.d. */
static inline int scene_occluded(const lc_scene* s, lc_ray ray, float dist) {
  lc_hit hit;
  return bvh_trace(s, ray.o, ray.d, 0.0f, dist, 1, &hit);
}

#endif
