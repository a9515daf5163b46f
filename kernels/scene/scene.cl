/* lucent kernel: the scene as the device sees it. Every buffer of shared/registry.h's
 * LC_SCENE_BUFFERS is a field of lc_scene and a kernel argument, in the registry's order, followed
 * by the launch parameters; src/render/device_scene.cpp sets the arguments from the same list. */
#ifndef LUCENT_SCENE_SCENE_CL
#define LUCENT_SCENE_SCENE_CL

#define LC_SCENE_FIELD(name, type, what) __global const type* name;
typedef struct {
  LC_SCENE_BUFFERS(LC_SCENE_FIELD)
  __global const lc_params* params;
} lc_scene;
#undef LC_SCENE_FIELD

/* The scene's kernel arguments: every scene buffer, then params. */
#define LC_SCENE_ARG(name, type, what) __global const type *name,
#define LC_SCENE_KERNEL_ARGS LC_SCENE_BUFFERS(LC_SCENE_ARG) __global const lc_params* params

/* The lc_scene of a kernel declared with LC_SCENE_KERNEL_ARGS. */
#define LC_SCENE_ARG_NAME(name, type, what) name,
#define LC_SCENE_FROM_KERNEL_ARGS \
  { LC_SCENE_BUFFERS(LC_SCENE_ARG_NAME) params }

/* An lc_scene holding only the geometry (probe kernels that trace rays or intersect primitives);
 * the other buffers are null. */
static inline lc_scene lc_scene_geometry(__global const lc_params* params,
                                         __global const lc_bvh_node* nodes,
                                         __global const lc_bvh_leaf* leaves,
                                         __global const lc_triangle* triangles,
                                         __global const lc_sphere* spheres) {
  lc_scene s = {0};
  s.params = params;
  s.nodes = nodes;
  s.leaves = leaves;
  s.triangles = triangles;
  s.spheres = spheres;
  return s;
}

#endif
