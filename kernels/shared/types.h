/*
 * lucent: host/device structs, written once in plain C and compiled both as C++ (host) and as
 * OpenCL C (device).
 *
 * Rules: every struct is POD, 16-byte aligned and a multiple of 16 bytes; no float3 or glm type
 * inside a buffer struct (float3 is 16 bytes on the device, 12 on the host); scalars only
 * (float, lc_int, lc_uint) and arrays of them. Sizes and offsets are checked by LC_STATIC_ASSERT
 * here on both sides, and tests/test_layout.cpp runs a kernel that reports sizeof/offsetof as the
 * device sees them and compares them with the host's.
 */
#ifndef LUCENT_SHARED_TYPES_H
#define LUCENT_SHARED_TYPES_H

#ifdef __OPENCL_C_VERSION__
typedef uint lc_uint;
typedef int lc_int;
#define LC_ALIGN16 __attribute__((aligned(16)))
#define LC_STATIC_ASSERT(cond, name) typedef char lc_static_assert_##name[(cond) ? 1 : -1]
#else
#include <cstdint>
typedef std::uint32_t lc_uint;
typedef std::int32_t lc_int;
#define LC_ALIGN16 alignas(16)
#define LC_STATIC_ASSERT(cond, name) static_assert(cond, #name)
#endif
#define LC_OFFSETOF(type, member) __builtin_offsetof(type, member)

#define LC_INVALID 0xffffffffu

#include "shared/registry.h"

/* Four floats: float4 on the device, 16 aligned bytes on the host (texels). */
#ifdef __OPENCL_C_VERSION__
typedef float4 lc_float4;
#else
typedef struct LC_ALIGN16 {
  float s[4];
} lc_float4;
#endif

/* ------------------------------------------------------------------------------------------ */
/* Registry enums and their checks                                                            */
/* ------------------------------------------------------------------------------------------ */
/* Device constants from shared/registry.h: LC_MAT_<ID>, LC_LIGHT_<ID>, LC_SHAPE_<ID>,
 * LC_INTEGRATOR_<ID> (integrators, then AOVs), LC_FILTER_<ID>, LC_SAMPLER_<ID>, and
 * LC_<CONCEPT>_COUNT. */
/* Every X macro below names all of its list's columns: the kernel is OpenCL C 1.2, which has no
 * variadic macros (NVIDIA's compiler refuses them; tests/test_kernel_source.cpp checks). Seven
 * columns: materials and lights (params), filters (radius); six: the other lists. */
#define LC_ENUM_MAT(ID, Name, value, name, feature, file, params) LC_MAT_##ID = value,
#define LC_ENUM_LIGHT(ID, Name, value, name, feature, file, params) LC_LIGHT_##ID = value,
#define LC_ENUM_SHAPE(ID, Name, value, name, feature, file) LC_SHAPE_##ID = value,
#define LC_ENUM_INTEGRATOR(ID, Name, value, name, feature, file) LC_INTEGRATOR_##ID = value,
#define LC_ENUM_FILTER(ID, Name, value, name, feature, file, radius) LC_FILTER_##ID = value,
#define LC_ENUM_SAMPLER(ID, Name, value, name, feature, file) LC_SAMPLER_##ID = value,
#define LC_ONE_6(ID, Name, value, name, feature, file) +1
#define LC_ONE_7(ID, Name, value, name, feature, file, extra) +1
enum { LC_MATERIAL_TYPES(LC_ENUM_MAT) LC_MAT_COUNT = 0 LC_MATERIAL_TYPES(LC_ONE_7) };
enum { LC_LIGHT_TYPES(LC_ENUM_LIGHT) LC_LIGHT_COUNT = 0 LC_LIGHT_TYPES(LC_ONE_7) };
enum { LC_SHAPE_TYPES(LC_ENUM_SHAPE) LC_SHAPE_COUNT = 0 LC_SHAPE_TYPES(LC_ONE_6) };
enum {
  LC_INTEGRATOR_TYPES(LC_ENUM_INTEGRATOR) LC_AOV_TYPES(LC_ENUM_INTEGRATOR)
  /* the first AOV: integrator values from here on are AOVs (integrator/aov.cl) */
  LC_INTEGRATOR_FIRST_AOV = 0 LC_INTEGRATOR_TYPES(LC_ONE_6),
  LC_INTEGRATOR_COUNT = 0 LC_INTEGRATOR_TYPES(LC_ONE_6) LC_AOV_TYPES(LC_ONE_6)
};
enum { LC_FILTER_TYPES(LC_ENUM_FILTER) LC_FILTER_COUNT = 0 LC_FILTER_TYPES(LC_ONE_7) };
enum { LC_SAMPLER_TYPES(LC_ENUM_SAMPLER) LC_SAMPLER_COUNT = 0 LC_SAMPLER_TYPES(LC_ONE_6) };

/* Each list's values are 0, 1, ..., count - 1 in list order: a sum of count powers of two is
 * 2^count - 1 only when they are exactly those (a repeated or missing value breaks it), and each
 * entry's value is compared with its position. */
#define LC_VALUE_BIT_6(ID, Name, value, name, feature, file) +(1u << (value))
#define LC_VALUE_BIT_7(ID, Name, value, name, feature, file, extra) +(1u << (value))
#define LC_POS_MAT(ID, Name, value, name, feature, file, params) LC_MAT_POS_##ID,
#define LC_POS_LIGHT(ID, Name, value, name, feature, file, params) LC_LIGHT_POS_##ID,
#define LC_POS_SHAPE(ID, Name, value, name, feature, file) LC_SHAPE_POS_##ID,
#define LC_POS_INTEGRATOR(ID, Name, value, name, feature, file) LC_INTEGRATOR_POS_##ID,
#define LC_POS_FILTER(ID, Name, value, name, feature, file, radius) LC_FILTER_POS_##ID,
#define LC_POS_SAMPLER(ID, Name, value, name, feature, file) LC_SAMPLER_POS_##ID,
enum { LC_MATERIAL_TYPES(LC_POS_MAT) LC_MAT_POS_END_ };
enum { LC_LIGHT_TYPES(LC_POS_LIGHT) LC_LIGHT_POS_END_ };
enum { LC_SHAPE_TYPES(LC_POS_SHAPE) LC_SHAPE_POS_END_ };
enum { LC_INTEGRATOR_TYPES(LC_POS_INTEGRATOR) LC_AOV_TYPES(LC_POS_INTEGRATOR) LC_INT_POS_END_ };
enum { LC_FILTER_TYPES(LC_POS_FILTER) LC_FILTER_POS_END_ };
enum { LC_SAMPLER_TYPES(LC_POS_SAMPLER) LC_SAMPLER_POS_END_ };
#define LC_CHECK_MAT(ID, Name, value, name, feature, file, params) \
  LC_STATIC_ASSERT((int)LC_MAT_##ID == (int)LC_MAT_POS_##ID, mat_order_##ID);
#define LC_CHECK_LIGHT(ID, Name, value, name, feature, file, params) \
  LC_STATIC_ASSERT((int)LC_LIGHT_##ID == (int)LC_LIGHT_POS_##ID, light_order_##ID);
#define LC_CHECK_SHAPE(ID, Name, value, name, feature, file) \
  LC_STATIC_ASSERT((int)LC_SHAPE_##ID == (int)LC_SHAPE_POS_##ID, shape_order_##ID);
#define LC_CHECK_INTEGRATOR(ID, Name, value, name, feature, file) \
  LC_STATIC_ASSERT((int)LC_INTEGRATOR_##ID == (int)LC_INTEGRATOR_POS_##ID, integrator_order_##ID);
#define LC_CHECK_FILTER(ID, Name, value, name, feature, file, radius) \
  LC_STATIC_ASSERT((int)LC_FILTER_##ID == (int)LC_FILTER_POS_##ID, filter_order_##ID);
#define LC_CHECK_SAMPLER(ID, Name, value, name, feature, file) \
  LC_STATIC_ASSERT((int)LC_SAMPLER_##ID == (int)LC_SAMPLER_POS_##ID, sampler_order_##ID);
LC_MATERIAL_TYPES(LC_CHECK_MAT)
LC_LIGHT_TYPES(LC_CHECK_LIGHT)
LC_SHAPE_TYPES(LC_CHECK_SHAPE)
LC_INTEGRATOR_TYPES(LC_CHECK_INTEGRATOR)
LC_AOV_TYPES(LC_CHECK_INTEGRATOR)
LC_FILTER_TYPES(LC_CHECK_FILTER)
LC_SAMPLER_TYPES(LC_CHECK_SAMPLER)
LC_STATIC_ASSERT((0u LC_MATERIAL_TYPES(LC_VALUE_BIT_7)) == (1u << LC_MAT_COUNT) - 1u,
                 material_values);
LC_STATIC_ASSERT((0u LC_LIGHT_TYPES(LC_VALUE_BIT_7)) == (1u << LC_LIGHT_COUNT) - 1u, light_values);
LC_STATIC_ASSERT((0u LC_SHAPE_TYPES(LC_VALUE_BIT_6)) == (1u << LC_SHAPE_COUNT) - 1u, shape_values);
LC_STATIC_ASSERT((0u LC_INTEGRATOR_TYPES(LC_VALUE_BIT_6) LC_AOV_TYPES(LC_VALUE_BIT_6)) ==
                     (1u << LC_INTEGRATOR_COUNT) - 1u,
                 integrator_values);
LC_STATIC_ASSERT((0u LC_FILTER_TYPES(LC_VALUE_BIT_7)) == (1u << LC_FILTER_COUNT) - 1u,
                 filter_values);
LC_STATIC_ASSERT((0u LC_SAMPLER_TYPES(LC_VALUE_BIT_6)) == (1u << LC_SAMPLER_COUNT) - 1u,
                 sampler_values);

/* ------------------------------------------------------------------------------------------ */
/* Materials                                                                                  */
/* ------------------------------------------------------------------------------------------ */
/* lc_<file>_params per material type (fields from the registry), and their union. A type's
 * parameters must fit in 48 bytes: the union keeps lc_material at 64. */
#define LC_MAT_PARAMS_STRUCT(ID, Name, value, name, feature, file, params) \
  typedef struct {                                                         \
    params                                                                 \
  } lc_##file##_params;
LC_MATERIAL_TYPES(LC_MAT_PARAMS_STRUCT)
#define LC_MAT_PARAMS_MEMBER(ID, Name, value, name, feature, file, params) lc_##file##_params file;
typedef union {
  LC_MATERIAL_TYPES(LC_MAT_PARAMS_MEMBER)
  float words[12];
} lc_material_params;
LC_STATIC_ASSERT(sizeof(lc_material_params) == 48, material_params_size);

typedef struct LC_ALIGN16 lc_material {
  float emission[3];    /* emitted radiance, linear RGB (any material may emit) */
  lc_uint type;         /* LC_MAT_*                                             */
  lc_material_params p; /* the type's parameters: p.<file> (shared/registry.h) */
} lc_material;          /* total: 64 bytes */
LC_STATIC_ASSERT(sizeof(lc_material) == 64, material_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_material, type) == 12, material_type);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_material, p) == 16, material_params);

/* ------------------------------------------------------------------------------------------ */
/* Geometry                                                                                   */
/* ------------------------------------------------------------------------------------------ */
typedef struct LC_ALIGN16 lc_sphere {
  float center[3];
  float radius;
  lc_uint material; /* index into materials                     */
  lc_uint light;    /* index into lights if emissive, LC_INVALID */
  lc_uint flags;    /* LC_SPHERE_TEXTURED                         */
  lc_uint texture;  /* textured: its material's albedo texture header, whose uv scale  */
                    /* and offset map the sphere's uvs (LC_HAS_TEXTURE_MAPPING)         */
} lc_sphere;        /* total: 32 bytes */
LC_STATIC_ASSERT(sizeof(lc_sphere) == 32, sphere_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_sphere, radius) == 12, sphere_radius);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_sphere, material) == 16, sphere_material);

/* lc_sphere.flags: its material reads textures, so hits need texture coordinates */
#define LC_SPHERE_TEXTURED 1u

#define LC_TRI_HAS_NORMALS 1u
#define LC_TRI_HAS_UVS 2u

/* One triangle as hits and lights read it: its three world-space vertices and its unit geometric
 * normal normalize((v1 - v0) x (v2 - v0)), computed on the host in double from the float
 * vertices (render_detail::set_triangle_normal); one 64-byte cache line. (Traversal reads the
 * vertices of lc_bvh_leaf instead.) Each vertex is a 16-byte row whose fourth float is a
 * component of the normal, so the kernel loads a vertex as one aligned float4 (lc_load3a). The
 * fourth lane of such a load is computed along with the others, so it must be an ordinary float:
 * an integer field there reads as a subnormal, and arithmetic on subnormals made renders 0.90x
 * (BENCHMARKS.md, "Aligned float3 loads"); the host flushes a subnormal component to 0. */
typedef struct LC_ALIGN16 lc_triangle {
  float v0[3];
  float ng_x; /* unit geometric normal, x                    */
  float v1[3];
  float ng_y; /* y                                           */
  float v2[3];
  float ng_z;       /* z                                           */
  lc_uint material; /* index into materials                     */
  lc_uint light;    /* index into lights if emissive, LC_INVALID */
  lc_uint flags;    /* LC_TRI_HAS_NORMALS | LC_TRI_HAS_UVS        */
  lc_uint pad;
} lc_triangle; /* total: 64 bytes */
LC_STATIC_ASSERT(sizeof(lc_triangle) == 64, triangle_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_triangle, ng_x) == 12, triangle_ng_x);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_triangle, v1) == 16, triangle_v1);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_triangle, ng_y) == 28, triangle_ng_y);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_triangle, v2) == 32, triangle_v2);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_triangle, ng_z) == 44, triangle_ng_z);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_triangle, material) == 48, triangle_material);

/* Shading data of one triangle, read only at the closest hit. */
typedef struct LC_ALIGN16 lc_triangle_attr {
  float n[9];           /* vertex normals n0, n1, n2 (world space, unit)  */
  float uv[6];          /* texture coordinates uv0, uv1, uv2              */
  lc_uint source_index; /* index in the scene's triangle list (degenerate triangles are
                           dropped at packing, so it can differ from the packed index) */
} lc_triangle_attr;     /* total: 64 bytes */
LC_STATIC_ASSERT(sizeof(lc_triangle_attr) == 64, triangle_attr_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_triangle_attr, uv) == 36, triangle_attr_uv);

/* Primitive references stored in BVH leaves: a triangle index, or a sphere index with this bit. */
#define LC_PRIM_SPHERE_BIT 0x80000000u

/*
 * Wide BVH node (LC_BVH_WIDTH children), built on the host by collapsing the binary SAH tree of
 * src/bvh/bvh_build.cpp (src/bvh/bvh_wide.cpp) and walked by kernels/bvh/traverse.cl, which tests
 * all children of a node with one vector operation per slab plane. nodes[0] is the root.
 *
 * bounds: the children's boxes, structure of arrays: row 0 min x, 1 max x, 2 min y, 3 max y,
 *   4 min z, 5 max z; column k is child k. The kernel loads row (0 or 1) + 2 axis whole, so the
 *   nearer plane of each axis is picked once per ray by the sign of its direction.
 * child: interior child: its node index; leaf: LC_BVH_LEAF_BIT | (blocks - 1) <<
 *   LC_BVH_LEAF_COUNT_SHIFT | index of its first lc_bvh_leaf block (a leaf of up to
 *   LC_BVH_LEAF_MAX primitives fills 1 to 4 consecutive blocks); unused slot: LC_INVALID with an
 *   empty box (min +inf, max -inf), which no ray enters.
 */
#define LC_BVH_WIDTH 8
#define LC_BVH_LEAF_BIT 0x80000000u
#define LC_BVH_LEAF_COUNT_SHIFT 27
#define LC_BVH_LEAF_MAX 16u                /* primitives per leaf, at most               */
#define LC_BVH_LEAF_FIRST_MASK 0x07ffffffu /* first block of a leaf                      */
#define LC_BVH_MAX_DEPTH 64 /* levels of the binary tree and so of the wide one, at most */

typedef struct LC_ALIGN16 lc_bvh_node {
  float bounds[6][LC_BVH_WIDTH]; /* child boxes, rows min x, max x, min y, max y, min z, max z */
  lc_uint child[LC_BVH_WIDTH];   /* node index, leaf reference or LC_INVALID (see above)       */
  lc_uint pad[LC_BVH_WIDTH];     /* unused: keeps nodes on 64-byte boundaries                  */
} lc_bvh_node;                   /* total: 256 bytes (LC_BVH_WIDTH 8; 128 bytes with 4) */
LC_STATIC_ASSERT(sizeof(lc_bvh_node) == 32 * LC_BVH_WIDTH, bvh_node_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_bvh_node, child) == 24 * LC_BVH_WIDTH, bvh_node_child);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_bvh_node, pad) == 28 * LC_BVH_WIDTH, bvh_node_pad);

/* Leaf block: 4 primitives of a leaf (fewer in its last block), their triangles' vertices as
 * structure of arrays so that one vector operation tests all four triangles.
 * v: rows v0.x, v0.y, v0.z, v1.x, v1.y, v1.z, v2.x, v2.y, v2.z; column k is primitive k (zeros for
 *   a sphere or an unused column).
 * prim: primitive reference (triangle index, or sphere index | LC_PRIM_SPHERE_BIT), LC_INVALID for
 *   an unused column. */
typedef struct LC_ALIGN16 lc_bvh_leaf {
  float v[9][4];   /* triangle vertices, one column per primitive */
  lc_uint prim[4]; /* primitive references                        */
} lc_bvh_leaf;     /* total: 160 bytes */
LC_STATIC_ASSERT(sizeof(lc_bvh_leaf) == 160, bvh_leaf_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_bvh_leaf, prim) == 144, bvh_leaf_prim);

/* ------------------------------------------------------------------------------------------ */
/* Lights                                                                                     */
/* ------------------------------------------------------------------------------------------ */
/* lc_<file>_light_params per light type (fields from the registry), and their union. */
#define LC_LIGHT_PARAMS_STRUCT(ID, Name, value, name, feature, file, params) \
  typedef struct {                                                           \
    params                                                                   \
  } lc_##file##_light_params;
LC_LIGHT_TYPES(LC_LIGHT_PARAMS_STRUCT)
#define LC_LIGHT_PARAMS_MEMBER(ID, Name, value, name, feature, file, params) \
  lc_##file##_light_params file;
typedef union {
  LC_LIGHT_TYPES(LC_LIGHT_PARAMS_MEMBER)
  float words[8];
} lc_light_params;
LC_STATIC_ASSERT(sizeof(lc_light_params) == 32, light_params_size);

typedef struct LC_ALIGN16 lc_light {
  lc_uint type;     /* LC_LIGHT_*                                               */
  float pdf_select; /* probability that light sampling picks this light         */
  lc_uint pad[2];
  lc_light_params p; /* the type's parameters: p.<file> (shared/registry.h)      */
} lc_light;          /* total: 48 bytes */
LC_STATIC_ASSERT(sizeof(lc_light) == 48, light_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_light, pdf_select) == 4, light_pdf_select);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_light, p) == 16, light_params);

/* ------------------------------------------------------------------------------------------ */
/* Textures: texels of every texture packed into one float4 buffer (linear RGBA). A header per */
/* (image, mapping): an image several materials map differently has several headers with the  */
/* same texels; the first ones, one per scene texture, map it by default (environment maps).  */
/* The mapping is read only with LC_HAS_TEXTURE_MAPPING (texture/texture.cl). A hit's uv is   */
/* in texture space (uv * uv_scale + uv_offset) before the lookup, which wraps it: the host   */
/* maps triangles' uvs (in double, then takes whole periods off: render_detail::pack_scene),  */
/* the kernel maps spheres' (texture_map_uv, with the header's uv_scale and uv_offset).       */
/* ------------------------------------------------------------------------------------------ */
/* wrap modes (lucent::TextureWrap): lc_texture.wrap holds u's in bits 0-7, v's in bits 8-15 */
#define LC_WRAP_REPEAT 0u
#define LC_WRAP_CLAMP 1u
#define LC_WRAP_MIRROR 2u
#define LC_WRAP_V_SHIFT 8u
typedef struct LC_ALIGN16 lc_texture {
  lc_uint offset; /* first texel in the texel buffer                             */
  lc_uint width;
  lc_uint height;
  lc_uint wrap;      /* LC_WRAP_* of u | LC_WRAP_* of v << LC_WRAP_V_SHIFT           */
  float uv_scale[2]; /* texture space is uv * uv_scale + uv_offset (spheres' uvs)     */
  float uv_offset[2];
} lc_texture; /* total: 32 bytes */
LC_STATIC_ASSERT(sizeof(lc_texture) == 32, texture_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_texture, uv_scale) == 16, texture_uv_scale);

/* ------------------------------------------------------------------------------------------ */
/* Camera and launch parameters                                                               */
/* ------------------------------------------------------------------------------------------ */
typedef struct LC_ALIGN16 lc_camera {
  float position[3];
  float tan_half_fov; /* tan(vertical fov / 2)                      */
  float right[3];     /* unit vector, image +x                      */
  float aspect;       /* width / height                             */
  float up[3];        /* unit vector, image +y                      */
  float lens_radius;  /* thin lens aperture radius, 0 = pinhole     */
  float forward[3];   /* unit vector, viewing direction             */
  float focus_distance;
} lc_camera; /* total: 64 bytes */
LC_STATIC_ASSERT(sizeof(lc_camera) == 64, camera_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_camera, right) == 16, camera_right);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_camera, forward) == 48, camera_forward);

typedef struct LC_ALIGN16 lc_params {
  lc_camera camera;
  lc_uint width;
  lc_uint height;
  lc_uint sample_offset;    /* index of the first sample of this pass             */
  lc_uint samples_per_pass; /* samples per pixel in this launch                   */
  lc_uint seed;
  lc_uint max_depth;
  lc_uint rr_depth;   /* Russian roulette starts at this depth             */
  lc_uint integrator; /* LC_INTEGRATOR_* (integrators, then AOVs)           */
  lc_uint num_triangles;
  lc_uint num_spheres;
  lc_uint num_lights;
  lc_uint num_nodes;
  lc_int env_light;    /* index of the environment light or -1              */
  lc_uint filter;      /* LC_FILTER_*                                        */
  float filter_radius; /* in pixels                                          */
  float ao_distance;   /* ambient occlusion ray length (INFINITY: unbounded) */
  lc_uint flags;
  lc_uint sampler;    /* LC_SAMPLER_*                                       */
  float clamp;        /* path: bound of a scattered contribution (0: off)   */
  lc_uint work_items; /* 0: every pixel; else the length of the work list  */
  lc_uint splits;     /* path: smooth-dielectric vertices split per branch, */
                      /* at most LC_MAX_SPLITS                              */
  lc_uint pad0, pad1, pad2;
} lc_params; /* total: 160 bytes */
LC_STATIC_ASSERT(sizeof(lc_params) == 160, params_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_params, width) == 64, params_width);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_params, num_triangles) == 96, params_num_triangles);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_params, env_light) == 112, params_env_light);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_params, filter) == 116, params_filter);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_params, sampler) == 132, params_sampler);

/* lc_params.splits: the most (the path integrator's stack of waiting branches holds them);
 * limits::kMaxDielectricSplits on the host, checked equal in src/render/pack.cpp */
#define LC_MAX_SPLITS 4

/* lc_params.flags */
#define LC_FLAG_NO_MIS 1u   /* path: light sampling only for area lights (no BSDF-hit emission) */
#define LC_FLAG_CAUSTICS 2u /* path: caustic paths by light tracing (integrator/caustics.cl) */

/* Counters accumulated by one launch (atomics on the device). Each is a 64-bit count in two
 * 32-bit words, as OpenCL 1.2 has no 64-bit atomics: the low word, and the high word, which the
 * work-item whose atomic_add carried out of the low word increments (megakernel.cl, lc_count64).
 * A pass of a large film at several samples per pixel traces more than 2^32 rays. */
#define LC_COUNTER_NONFINITE 0      /* samples whose radiance was NaN or Inf (not in the film) */
#define LC_COUNTER_RAYS 1           /* rays traced, shadow rays included                        */
#define LC_COUNTER_NONFINITE_HIGH 2 /* the high word of LC_COUNTER_NONFINITE's count            */
#define LC_COUNTER_RAYS_HIGH 3      /* the high word of LC_COUNTER_RAYS's count                 */
#define LC_COUNTER_COUNT 4

#endif /* LUCENT_SHARED_TYPES_H */
