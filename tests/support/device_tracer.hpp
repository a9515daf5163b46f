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
  /// Uploads the scene and builds the trace kernel, with `build_options` added to the OpenCL
  /// build options (e.g. "-D LC_DOUBLE"), through the program cache in `cache_dir` ("" none).
  /// Throws lucent::Error.
  DeviceTracer(const cl_util::Context& ctx, const std::vector<lc_triangle>& triangles,
               const std::vector<lc_sphere>& spheres, const Bvh& bvh,
               const std::string& build_options = "", const std::string& cache_dir = "");
  /// Closest hits, or with any_hit only occlusion (prim != LC_INVALID when occluded).
  std::vector<TraceHit> trace(const std::vector<TraceRay>& rays, bool any_hit = false);
  /// Seconds the last trace() spent in the kernel alone (rays already on the device).
  double last_kernel_seconds() const { return kernel_seconds_; }

 private:
  const cl_util::Context& ctx_;
  cl::Kernel kernel_;
  cl::Buffer params_, nodes_, leaves_, tris_, spheres_;
  double kernel_seconds_ = 0;
};

}  // namespace lucent::bvh
