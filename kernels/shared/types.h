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

/* ------------------------------------------------------------------------------------------ */
/* Materials                                                                                  */
/* ------------------------------------------------------------------------------------------ */
#define LC_MAT_DIFFUSE 0u    /* Lambertian: albedo (or albedo_tex)                               */
#define LC_MAT_MIRROR 1u     /* perfect specular reflection, RGB reflectance in specular          */
#define LC_MAT_DIELECTRIC 2u /* Fresnel glass: ior, tint in specular                              */
#define LC_MAT_CONDUCTOR 3u  /* GGX microfacet conductor: specular = F0 colour, roughness         */
#define LC_MAT_PLASTIC 4u    /* GGX coating over a diffuse base: albedo, specular, roughness, ior */

typedef struct LC_ALIGN16 lc_material {
  float albedo[3];   /* diffuse colour, linear RGB                                   */
  lc_int albedo_tex; /* texture index or -1                                          */
  float emission[3]; /* emitted radiance, linear RGB (any material may emit)        */
  lc_uint type;      /* LC_MAT_*                                                     */
  float specular[3]; /* mirror reflectance / glass tint / glossy specular colour     */
  float ior;         /* index of refraction (dielectric, plastic)                    */
  float roughness;   /* GGX alpha (conductor, plastic)                               */
  lc_uint flags;     /* reserved                                                     */
  lc_uint pad0;
  lc_uint pad1;
} lc_material; /* total: 64 bytes */
LC_STATIC_ASSERT(sizeof(lc_material) == 64, material_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_material, emission) == 16, material_emission);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_material, type) == 28, material_type);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_material, specular) == 32, material_specular);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_material, roughness) == 48, material_roughness);

/* ------------------------------------------------------------------------------------------ */
/* Geometry                                                                                   */
/* ------------------------------------------------------------------------------------------ */
typedef struct LC_ALIGN16 lc_sphere {
  float center[3];
  float radius;
  lc_uint material; /* index into materials                     */
  lc_uint light;    /* index into lights if emissive, LC_INVALID */
  lc_uint pad0;
  lc_uint pad1;
} lc_sphere; /* total: 32 bytes */
LC_STATIC_ASSERT(sizeof(lc_sphere) == 32, sphere_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_sphere, radius) == 12, sphere_radius);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_sphere, material) == 16, sphere_material);

#define LC_TRI_HAS_NORMALS 1u
#define LC_TRI_HAS_UVS 2u

/* Intersection data of one triangle: its three world-space vertices. */
typedef struct LC_ALIGN16 lc_triangle {
  float v0[3];
  lc_uint material; /* index into materials                     */
  float v1[3];
  lc_uint light; /* index into lights if emissive, LC_INVALID */
  float v2[3];
  lc_uint flags; /* LC_TRI_HAS_NORMALS | LC_TRI_HAS_UVS        */
} lc_triangle; /* total: 48 bytes */
LC_STATIC_ASSERT(sizeof(lc_triangle) == 48, triangle_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_triangle, v1) == 16, triangle_v1);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_triangle, v2) == 32, triangle_v2);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_triangle, flags) == 44, triangle_flags);

/* Shading data of one triangle, read only at the closest hit. */
typedef struct LC_ALIGN16 lc_triangle_attr {
  float n[9];  /* vertex normals n0, n1, n2 (world space, unit)  */
  float uv[6]; /* texture coordinates uv0, uv1, uv2              */
  lc_uint source_index; /* index in the scene's triangle list (degenerate triangles are
                           dropped at packing, so it can differ from the packed index) */
} lc_triangle_attr; /* total: 64 bytes */
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
} lc_bvh_node; /* total: 256 bytes (LC_BVH_WIDTH 8; 128 bytes with 4) */
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
} lc_bvh_leaf; /* total: 160 bytes */
LC_STATIC_ASSERT(sizeof(lc_bvh_leaf) == 160, bvh_leaf_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_bvh_leaf, prim) == 144, bvh_leaf_prim);

/* ------------------------------------------------------------------------------------------ */
/* Lights                                                                                     */
/* ------------------------------------------------------------------------------------------ */
#define LC_LIGHT_POINT 0u    /* position, intensity (W/sr)                              */
#define LC_LIGHT_SPHERE 1u   /* emissive sphere: prim = sphere index                    */
#define LC_LIGHT_TRIANGLE 2u /* emissive triangle: prim = triangle index                */
#define LC_LIGHT_ENV 3u      /* constant environment: radiance in intensity             */
#define LC_LIGHT_ENV_MAP 4u  /* equirectangular environment map: texture, scale        */

typedef struct LC_ALIGN16 lc_light {
  float position[3];  /* point light position                                        */
  lc_uint type;       /* LC_LIGHT_*                                                  */
  float intensity[3]; /* point: intensity; area/env: radiance (scale for maps)        */
  lc_uint prim;       /* sphere or triangle index for area lights                     */
  float pdf_select;   /* probability that light sampling picks this light (∝ power)   */
  float area;         /* surface area for area lights                                 */
  lc_int texture;     /* environment map texture or -1                               */
  lc_uint pad0;
} lc_light; /* total: 48 bytes */
LC_STATIC_ASSERT(sizeof(lc_light) == 48, light_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_light, intensity) == 16, light_intensity);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_light, pdf_select) == 32, light_pdf_select);

/* ------------------------------------------------------------------------------------------ */
/* Textures: texels of every texture packed into one float4 buffer (linear RGBA).             */
/* ------------------------------------------------------------------------------------------ */
typedef struct LC_ALIGN16 lc_texture {
  lc_uint offset; /* first texel in the texel buffer */
  lc_uint width;
  lc_uint height;
  lc_uint flags;
} lc_texture; /* total: 16 bytes */
LC_STATIC_ASSERT(sizeof(lc_texture) == 16, texture_size);

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

#define LC_INTEGRATOR_PATH 0u
#define LC_INTEGRATOR_WHITTED 1u
#define LC_INTEGRATOR_DIRECT 2u /* point lights only, no indirect: first renders */
#define LC_INTEGRATOR_ALBEDO 3u
#define LC_INTEGRATOR_NORMAL 4u
#define LC_INTEGRATOR_DEPTH 5u
#define LC_INTEGRATOR_AO 6u
#define LC_INTEGRATOR_PRIMITIVE 7u /* scene-order primitive index + 1 of the first hit */

#define LC_FILTER_BOX 0u
#define LC_FILTER_TENT 1u
#define LC_FILTER_GAUSSIAN 2u

typedef struct LC_ALIGN16 lc_params {
  lc_camera camera;
  lc_uint width;
  lc_uint height;
  lc_uint sample_offset;     /* index of the first sample of this pass             */
  lc_uint samples_per_pass;  /* samples per pixel in this launch                   */
  lc_uint seed;
  lc_uint max_depth;
  lc_uint rr_depth;          /* Russian roulette starts at this depth             */
  lc_uint integrator;        /* LC_INTEGRATOR_*                                    */
  lc_uint num_triangles;
  lc_uint num_spheres;
  lc_uint num_lights;
  lc_uint num_nodes;
  float env_radiance[3];     /* constant environment radiance (0 when none)        */
  lc_int env_light;          /* index of the environment light or -1              */
  lc_uint filter;            /* LC_FILTER_*                                        */
  float filter_radius;       /* in pixels                                          */
  float ao_distance;         /* ambient occlusion ray length (INFINITY: unbounded) */
  lc_uint flags;
} lc_params; /* total: 144 bytes */
LC_STATIC_ASSERT(sizeof(lc_params) == 144, params_size);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_params, width) == 64, params_width);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_params, num_triangles) == 96, params_num_triangles);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_params, env_radiance) == 112, params_env_radiance);
LC_STATIC_ASSERT(LC_OFFSETOF(lc_params, filter) == 128, params_filter);

/* lc_params.flags */
#define LC_FLAG_NO_MIS 1u /* path: light sampling only for area lights (no BSDF-hit emission) */

/* Counters accumulated by one launch (atomics on the device). */
#define LC_COUNTER_NONFINITE 0 /* samples whose radiance was NaN or Inf (not added to the film) */
#define LC_COUNTER_RAYS 1      /* rays traced, shadow rays included                              */
#define LC_COUNTER_COUNT 4

#endif /* LUCENT_SHARED_TYPES_H */
