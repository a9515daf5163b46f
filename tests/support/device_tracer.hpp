#pragma once
// Traces batches of rays through the kernel traversal (kernels/test/trace_rays.cl) on one OpenCL
// device: the tests compare it with a brute-force reference, the benchmark times it.
#include <array>
#include <string>
#include <vector>

#include "bvh/bvh.hpp"
#include "cl/context.hpp"

namespace lucent::bvh {

struct TraceRay {
  float o[3];
  float tmax;
  float d[3];  ///< unit length
  float pad;
};

struct TraceHit {
  float t;
  lc_uint prim;  ///< triangle index or sphere index | LC_PRIM_SPHERE_BIT; LC_INVALID: miss
  float b1, b2;
};

class DeviceTracer {
 public:
  /// Uploads the scene and builds the trace kernel with the device's defines, as the renderer
  /// builds its own (render_detail::device_defines; without them when `device_defines` is false:
  /// the portable form of everything), then `build_options` (e.g. "-D LC_DOUBLE"), through the
  /// program cache in `cache_dir` ("" none), from the kernel sources in `kernel_dir` ("" the
  /// embedded ones). Throws lucent::Error.
  DeviceTracer(const cl_util::Context& ctx, const std::vector<lc_triangle>& triangles,
               const std::vector<lc_sphere>& spheres, const Bvh& bvh,
               const std::string& build_options = "", const std::string& cache_dir = "",
               const std::string& kernel_dir = "", bool device_defines = true);
  /// Closest hits, or with any_hit only occlusion (prim != LC_INVALID when occluded).
  std::vector<TraceHit> trace(const std::vector<TraceRay>& rays, bool any_hit = false);
  /// Seconds the last trace() spent in the kernel alone (rays already on the device).
  double last_kernel_seconds() const { return kernel_seconds_; }
  /// Whether this build traverses with the mask reductions of PoCL's x86-64 CPU device
  /// (kernels/bvh/traverse.cl, LC_BVH_MOVMSK) rather than the portable ones.
  bool mask_intrinsics();

 private:
  const cl_util::Context& ctx_;
  cl::Program program_;
  cl::Kernel kernel_;
  cl::Buffer params_, nodes_, leaves_, tris_, spheres_;
  double kernel_seconds_ = 0;
};

}  // namespace lucent::bvh
