#pragma once
// Kernel features: the LC_HAS_* defines a scene's megakernel is compiled with, and the build
// options. Every feature comes from the registries (kernels/shared/registry.h): the feature column
// of each type list and LC_OTHER_FEATURES.
#include <string>
#include <vector>

#include "lucent/device.hpp"
#include "lucent/render.hpp"
#include "lucent/scene.hpp"

namespace lucent::render_detail {

struct PackedScene;

/// Every kernel feature, once each, in registry order: what --no-specialize compiles.
const std::vector<std::string>& all_features();

/// The kernel features (LC_HAS_... defines) the scene uses: the types of its shapes, of the
/// materials some shape uses, of its lights, filter and integrator, and the other features its
/// data needs.
std::vector<std::string> scene_features(const Scene& scene, const PackedScene& packed);

/// Whether scene_features can differ between two cameras of the same scene. The features read
/// the camera only through this (a lens: aperture > 0), so that Renderer::set_camera knows
/// without scanning a large packing again that a move keeps the kernel.
bool camera_features_differ(const Camera& a, const Camera& b);

/// OpenCL build options (" -D LC_HAS_..." ...) for the scene's features, or for all of them.
std::string feature_defines(const Scene& scene, const PackedScene& packed, bool specialize = true);

/// The megakernel's full OpenCL build options for these render options: -cl-std, the feature
/// defines, -D LC_DOUBLE with Precision::Double, -cl-fast-relaxed-math with fast_math. They are
/// part of the program cache key, so each precision has its own cached binary.
std::string build_options(const Scene& scene, const PackedScene& packed,
                          const RenderOptions& options);

/// The build options that depend on the device, added to build_options' for each device's build
/// (and so to its cache key): " -D LC_DEVICE_POCL_CPU" for PoCL's CPU device (kernels/util/math.cl,
/// LC_POCL_NOINLINE: measured for PoCL's build time, wrong on Intel's CPU runtime; on x86-64 also
/// the traversal's mask reductions by movmskps and popcnt, kernels/bvh/traverse.cl),
/// " -D LC_ACCUM_DOUBLE" for a device with fp64 (a pass's sums in double, kernels/megakernel.cl;
/// the session reads them back as double4), and " -D LC_LIGHT_DOUBLE" for one with fp64 and
/// 64-bit atomics (cl_khr_int64_base_atomics: the caustics' light sums in double, added by a
/// 64-bit compare-and-swap, kernels/integrator/caustics.cl; read back as double4 too).
std::string device_defines(const DeviceInfo& device);

/// Whether `device`'s kernels keep the caustics' light sums in double (LC_LIGHT_DOUBLE: fp64 and
/// cl_khr_int64_base_atomics): the one rule for the define, the session's read-back and the
/// memory estimate.
bool light_sums_double(const DeviceInfo& device);

/// Throws lucent::Error (one line naming the device) when `precision` needs what the device lacks:
/// Precision::Double needs fp64 (cl_khr_fp64 / CL_DEVICE_DOUBLE_FP_CONFIG).
void check_precision_support(const DeviceInfo& device, Precision precision);

}  // namespace lucent::render_detail
