/*
 * lucent: the type registries. Every concept that has several types (materials, lights, shapes,
 * integrators, AOVs, filters, samplers) and the list of scene buffers is named here once, in plain
 * C, and expanded wherever a type is named: device enums and parameter structs (shared/types.h),
 * the kernel's dispatch (bsdf/bsdf.cl, light/light.cl, geom/interaction.cl,
 * integrator/integrator.cl, film/filter.cl) and per-type file list (src/cl/kernel_source.cpp), the
 * public C++ enums (include/lucent/scene.hpp), scene-file names, feature defines
 * (src/render/features.cpp), `lucent info`, the CLI and `lucent converge`, and the reference
 * integrator's dispatch. docs/adding-a-type.md says how to add an entry. Compiled as OpenCL C and
 * as C++; installed as <lucent/registry.h> because the public enums are generated from it.
 *
 * Every list is an X-macro: LC_MATERIAL_TYPES(X) expands X(...) once per entry, in order. The
 * columns common to the type lists are
 *   ID       the device constant's suffix (LC_MAT_<ID>, LC_LIGHT_<ID>, ...)
 *   Name     the public C++ enumerator (lucent::MaterialType::<Name>, ...)
 *   value    the enum value on both sides: the entries of a list take 0, 1, 2, ... in order
 *            (checked in shared/types.h), so a binary cache or a packed scene never mixes them up
 *   name     the name in scene files, on the command line and in `lucent info`
 *   feature  the kernel feature define (-D LC_HAS_...) that compiles the type in; a scene's
 *            kernel gets the defines of the types it uses (--no-specialize: all of them)
 *   file     the type's file and function prefix: kernels/<concept>/<file>.cl defines
 *            <concept>_<file>_... functions; src/scene/ and src/reference/ use it the same way
 * Materials and lights add their device parameters: LC_PARAMS(fields) becomes the struct
 * lc_<file>_params, a member of the union in lc_material / lc_light (plain scalars and arrays of
 * them only, no float3: see shared/types.h).
 */
#ifndef LUCENT_SHARED_REGISTRY_H
#define LUCENT_SHARED_REGISTRY_H

/* ------------------------------------------------------------------------------------------ */
/* Materials: X(ID, Name, value, name, feature, file, params)                                  */
/* The kernel's BSDF is kernels/bsdf/<file>.cl, the reference's src/reference/bsdf/<file>.cpp,  */
/* the scene-file parameters and their packing src/scene/materials/<file>.cpp.                 */
/* ------------------------------------------------------------------------------------------ */
#define LC_MATERIAL_TYPES(X)                                                                       \
  X(DIFFUSE, Diffuse, 0, "diffuse", LC_HAS_DIFFUSE, diffuse,                                       \
    LC_PARAMS(float albedo[3]; /* linear RGB */ lc_int albedo_tex; /* texture or -1 */))           \
  X(MIRROR, Mirror, 1, "mirror", LC_HAS_MIRROR, mirror,                                            \
    LC_PARAMS(float reflectance[3]; /* RGB reflectance */))                                        \
  X(DIELECTRIC, Dielectric, 2, "dielectric", LC_HAS_DIELECTRIC, dielectric,                        \
    LC_PARAMS(float tint[3]; /* transmission colour */ float ior;))                                \
  X(CONDUCTOR, Conductor, 3, "conductor", LC_HAS_CONDUCTOR, conductor,                             \
    LC_PARAMS(float f0[3]; /* Schlick F0 colour */ float roughness; /* GGX alpha */))              \
  X(PLASTIC, Plastic, 4, "plastic", LC_HAS_PLASTIC, plastic,                                       \
    LC_PARAMS(float albedo[3]; lc_int albedo_tex; float specular[3]; float ior; float roughness;)) \
  X(ROUGH_DIELECTRIC, RoughDielectric, 5, "rough_dielectric", LC_HAS_ROUGH_DIELECTRIC,             \
    rough_dielectric, LC_PARAMS(float tint[3]; float ior; float roughness;))                       \
  X(DIFFUSE_MIRROR, DiffuseMirror, 6, "diffuse_mirror", LC_HAS_DIFFUSE_MIRROR, diffuse_mirror,     \
    LC_PARAMS(float albedo[3]; lc_int albedo_tex; float reflectance[3];))

/* ------------------------------------------------------------------------------------------ */
/* Lights: X(ID, Name, value, name, feature, file, params)                                     */
/* Point lights and environments come from the scene's "lights"; sphere and triangle lights   */
/* are the emissive shapes (a material with "emission"). kernels/light/<file>.cl samples them. */
/* ------------------------------------------------------------------------------------------ */
#define LC_LIGHT_TYPES(X)                                                                   \
  X(POINT, Point, 0, "point", LC_HAS_POINT_LIGHTS, point,                                   \
    LC_PARAMS(float position[3]; float intensity[3]; /* W/sr */))                           \
  X(SPHERE, Sphere, 1, "sphere", LC_HAS_SPHERE_LIGHTS, sphere,                              \
    LC_PARAMS(lc_uint sphere; /* index into spheres */ float radiance[3];))                 \
  X(TRIANGLE, Triangle, 2, "triangle", LC_HAS_TRIANGLE_LIGHTS, triangle,                    \
    LC_PARAMS(lc_uint triangle; /* index into triangles */ float radiance[3]; float area;)) \
  X(ENV, Environment, 3, "environment", LC_HAS_ENV, env, LC_PARAMS(float radiance[3];))     \
  X(ENV_MAP, EnvironmentMap, 4, "environment_map", LC_HAS_ENV_MAP, env_map,                 \
    LC_PARAMS(float scale[3]; lc_int texture; /* equirectangular image */                   \
              lc_uint cdf;                                                                  \
              /* first of its width * height + 1 entries in light_cdf */))

/* ------------------------------------------------------------------------------------------ */
/* Shapes: X(ID, Name, value, name, feature, file)                                             */
/* kernels/geom/<file>.cl: intersection and the surface at a hit. Mesh files and inline       */
/* triangle lists both become triangles.                                                      */
/* ------------------------------------------------------------------------------------------ */
#define LC_SHAPE_TYPES(X)                                \
  X(SPHERE, Sphere, 0, "sphere", LC_HAS_SPHERES, sphere) \
  X(TRIANGLE, Triangle, 1, "triangles", LC_HAS_TRIANGLES, triangle)

/* ------------------------------------------------------------------------------------------ */
/* Integrators: X(ID, Name, value, name, feature, file)                                        */
/* kernels/integrator/<file>.cl defines integrator_<file>(); the AOVs below share one kernel   */
/* integrator (integrator/aov.cl) and follow the integrators in the same enum.                */
/* ------------------------------------------------------------------------------------------ */
#define LC_INTEGRATOR_TYPES(X)                                          \
  X(PATH, Path, 0, "path", LC_HAS_INTEGRATOR_PATH, path)                \
  X(WHITTED, Whitted, 1, "whitted", LC_HAS_INTEGRATOR_WHITTED, whitted) \
  X(DIRECT, Direct, 2, "direct", LC_HAS_INTEGRATOR_DIRECT, direct)

/* AOVs (arbitrary output variables of the first hit): X(ID, Name, value, name, feature, file);
 * their values continue the integrators'; integrator/aov.cl defines aov_<file>(). */
#define LC_AOV_TYPES(X)                                         \
  X(ALBEDO, Albedo, 3, "albedo", LC_HAS_INTEGRATOR_AOV, albedo) \
  X(NORMAL, Normal, 4, "normal", LC_HAS_INTEGRATOR_AOV, normal) \
  X(DEPTH, Depth, 5, "depth", LC_HAS_INTEGRATOR_AOV, depth)     \
  X(AO, Ao, 6, "ao", LC_HAS_INTEGRATOR_AOV, ao)                 \
  X(PRIMITIVE, Primitive, 7, "primitive", LC_HAS_INTEGRATOR_AOV, primitive)

/* ------------------------------------------------------------------------------------------ */
/* Pixel filters: X(ID, Name, value, name, feature, file, default radius in pixels)            */
/* kernels/film/filter.cl defines filter_sample_<file>().                                      */
/* ------------------------------------------------------------------------------------------ */
#define LC_FILTER_TYPES(X)                                \
  X(BOX, Box, 0, "box", LC_HAS_FILTER_BOX, box, 0.5)      \
  X(TENT, Tent, 1, "tent", LC_HAS_FILTER_TENT, tent, 1.5) \
  X(GAUSSIAN, Gaussian, 2, "gaussian", LC_HAS_FILTER_GAUSSIAN, gaussian, 1.5)

/* ------------------------------------------------------------------------------------------ */
/* Samplers: X(ID, Name, value, name, feature, file)                                           */
/* The random numbers of a camera sample (shared/rng.h: lc_<file>_pair; the kernel's four     */
/* pairs at once: lc_<file>_pairs4 in sampler/sampler.cl): Owen-scrambled Sobol               */
/* (the default) or independent numbers (what the statistical tests assume). The kernel       */
/* (sampler/sampler.cl) and the reference (src/reference/sampler.hpp) draw the same numbers.  */
/* ------------------------------------------------------------------------------------------ */
#define LC_SAMPLER_TYPES(X)                                \
  X(SOBOL, Sobol, 0, "sobol", LC_HAS_SAMPLER_SOBOL, sobol) \
  X(INDEPENDENT, Independent, 1, "independent", LC_HAS_SAMPLER_INDEPENDENT, independent)

#endif /* LUCENT_SHARED_REGISTRY_H */

/* The kernel's and the library's part: its helper macros and the lists no public header uses.
 * Left out where LUCENT_REGISTRY_TYPES_ONLY is defined, as lucent/scene.hpp defines it to include
 * the type lists alone, so that a program that includes lucent's headers gets no LC_ENABLED,
 * LC_PARAMS, LC_SCENE_BUFFERS, ... of the kernel's (they were defined in every such file). Its
 * own guard: a library file that included lucent/scene.hpp first gets it when it includes this
 * header. */
#if !defined(LUCENT_REGISTRY_TYPES_ONLY) && !defined(LUCENT_SHARED_REGISTRY_KERNEL_PART)
#define LUCENT_SHARED_REGISTRY_KERNEL_PART

/* LC_ENABLED(LC_HAS_X) is 1 when the feature define LC_HAS_X is set to 1 (as -D LC_HAS_X does;
 * a define in a source file must say `#define LC_HAS_X 1`) and 0 otherwise, so that generated
 * dispatch code can test a feature in an expression
 * (`if (LC_ENABLED(feature) && type == ...)`), which the compiler folds: a type that is not
 * enabled costs no code. The feature's expansion is pasted onto LC_ON_: a set feature gives
 * LC_ON_1, which is 1; one that is not set stays a name, LC_ON_LC_HAS_X, which
 * generated/features_off.cl (written by src/cl/kernel_source.cpp from every feature column and
 * LC_OTHER_FEATURES) defines as 0. Kernel code only: the kernel is OpenCL C 1.2, which has no
 * variadic macros (NVIDIA's compiler refuses them), so the Linux kernel's IS_ENABLED technique,
 * which needs one, is not used. */
#define LC_ON_1 1
#define LC_ENABLED(feature) LC_ENABLED_1(feature)
#define LC_ENABLED_1(value) LC_ON_##value
#ifdef __OPENCL_C_VERSION__
#include "generated/features_off.cl"
#endif

/* The fields of a parameter struct, written inside one registry entry: declarations ending in
 * `;`, one name per declaration (no commas: the fields are one macro argument). */
#define LC_PARAMS(fields) fields

/* ------------------------------------------------------------------------------------------ */
/* Other kernel features: X(feature, what). With the type lists' feature column they make every   */
/* feature define (src/render/features.cpp decides which a scene uses).                         */
/* ------------------------------------------------------------------------------------------ */
#define LC_OTHER_FEATURES(X)                                             \
  X(LC_HAS_SMOOTH_NORMALS, "interpolated vertex normals")                \
  X(LC_HAS_UVS, "texture coordinates of triangles")                      \
  X(LC_HAS_TEXTURES, "textured materials")                               \
  X(LC_HAS_TEXTURE_MAPPING, "texture wrap modes, uv scales and offsets") \
  X(LC_HAS_THIN_LENS, "thin-lens depth of field")                        \
  X(LC_HAS_CLAMP, "clamped path contributions (integrator.clamp)")       \
  X(LC_HAS_CAUSTICS, "caustics by light tracing (integrator.caustics)")  \
  X(LC_HAS_SPLITTING, "both lobes of smooth glass on camera paths (integrator.dielectric_splits)")

/* ------------------------------------------------------------------------------------------ */
/* Scene buffers: X(name, element type, what)                                                  */
/* The device arrays of a packed scene, in kernel-argument order: the fields of lc_scene and   */
/* LC_SCENE_KERNEL_ARGS (scene/scene.cl), PackedScene and DeviceScene (src/render/). The      */
/* launch parameters (lc_params) follow them as the last scene argument. `what` names the     */
/* buffer in messages (a scene too large for the device).                                     */
/* ------------------------------------------------------------------------------------------ */
#define LC_SCENE_BUFFERS(X)                                                  \
  X(nodes, lc_bvh_node, "BVH nodes")                                         \
  X(leaves, lc_bvh_leaf, "BVH leaf blocks")                                  \
  X(triangles, lc_triangle, "triangles")                                     \
  X(tri_attrs, lc_triangle_attr, "triangle normals and uvs")                 \
  X(spheres, lc_sphere, "spheres")                                           \
  X(materials, lc_material, "materials")                                     \
  X(lights, lc_light, "lights")                                              \
  X(light_cdf, float, "light selection and environment-map sampling tables") \
  X(textures, lc_texture, "texture headers")                                 \
  X(texels, lc_float4, "texture texels")

#endif /* LUCENT_SHARED_REGISTRY_KERNEL_PART */
