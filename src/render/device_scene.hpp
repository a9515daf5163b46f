#pragma once
// A packed scene's buffers on an OpenCL device, in the argument order of every kernel that takes
// a scene: params, nodes, leaves, triangles, tri_attrs, spheres, materials, lights,
// light_cdf, textures, texels (kernels/megakernel.cl, kernels/test/*_probe.cl).
#include "cl/context.hpp"
#include "render/pack.hpp"

namespace lucent::render_detail {

struct DeviceScene {
  static constexpr int kArgCount = 11;
  cl::Buffer params, nodes, leaves, triangles, tri_attrs, spheres, materials, lights, light_cdf,
      textures, texels;

  /// Creates the buffers with their contents (copied at creation).
  DeviceScene(const cl_util::Context& ctx, const PackedScene& packed);

  /// Sets kernel arguments first .. first + kArgCount - 1; returns the next argument index.
  int set_args(cl::Kernel& kernel, int first = 0) const;
};

}  // namespace lucent::render_detail
