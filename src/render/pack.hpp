#pragma once
// Scene -> device buffers: the float, 16-byte aligned layout of kernels/shared/types.h.
#include <array>
#include <string>
#include <vector>

#include "bvh/bvh.hpp"
#include "lucent/device.hpp"
#include "lucent/render.hpp"
#include "lucent/scene.hpp"
#include "shared/types.h"

namespace lucent::render_detail {

struct PackedScene {
  lc_params params{};
  std::vector<lc_triangle> triangles;
  std::vector<lc_triangle_attr> tri_attrs;
  std::vector<lc_sphere> spheres;
  std::vector<lc_material> materials;
  std::vector<lc_light> lights;
  std::vector<float> light_cdf;  ///< cumulative selection probabilities, last = 1
  std::vector<lc_texture> textures;
  std::vector<std::array<float, 4>> texels;
  bvh::Bvh bvh;
  std::size_t skipped_triangles = 0;  ///< degenerate or non-finite, left out with a warning
};

/// The camera basis (right, up, forward, with roll applied) as the kernel uses it.
lc_camera pack_camera(const Camera& camera, int width, int height);

/// Converts and validates the scene, builds the BVH and the light table.
PackedScene pack_scene(const Scene& scene);

/// The kernel features (LC_HAS_... defines) the scene uses.
std::vector<std::string> scene_features(const Scene& scene, const PackedScene& packed);

/// Every kernel feature: what --no-specialize compiles.
const std::vector<std::string>& all_features();

/// OpenCL build options (" -D LC_HAS_..." ...) for the scene's features, or for all of them.
std::string feature_defines(const Scene& scene, const PackedScene& packed, bool specialize = true);

/// The megakernel's full OpenCL build options for these render options: -cl-std, the feature
/// defines, -D LC_DOUBLE with Precision::Double, -cl-fast-relaxed-math with fast_math. They are
/// part of the program cache key, so each precision has its own cached binary.
std::string build_options(const Scene& scene, const PackedScene& packed,
                          const RenderOptions& options);

/// Throws lucent::Error (one line naming the device) when `precision` needs what the device lacks:
/// Precision::Double needs fp64 (cl_khr_fp64 / CL_DEVICE_DOUBLE_FP_CONFIG).
void check_precision_support(const DeviceInfo& device, Precision precision);

}  // namespace lucent::render_detail
