#pragma once
// A packed scene's buffers on an OpenCL device, in the argument order of every kernel that takes
// a scene (LC_SCENE_KERNEL_ARGS, kernels/scene/scene.cl): the buffers of LC_SCENE_BUFFERS
// (kernels/shared/registry.h) in their order, then params.
#include "cl/context.hpp"
#include "render/pack.hpp"

namespace lucent::render_detail {

struct DeviceScene {
#define LUCENT_COUNT_BUFFER(name, type, ...) +1
  static constexpr int kArgCount = 1 LC_SCENE_BUFFERS(LUCENT_COUNT_BUFFER);
#undef LUCENT_COUNT_BUFFER
#define LUCENT_DEVICE_BUFFER(name, type, ...) cl::Buffer name;
  LC_SCENE_BUFFERS(LUCENT_DEVICE_BUFFER)
#undef LUCENT_DEVICE_BUFFER
  cl::Buffer params;

  /// Creates the buffers with their contents (copied at creation).
  DeviceScene(const cl_util::Context& ctx, const PackedScene& packed);

  struct Upload {
    int buffers = 0;        ///< buffers written
    std::size_t bytes = 0;  ///< bytes written
  };
  /// Brings the buffers from `previous` (what they hold) to `packed`: writes those whose contents
  /// differ, recreating those whose size changed. The kernel arguments must be set again after.
  Upload update(const cl_util::Context& ctx, const PackedScene& previous,
                const PackedScene& packed);

  /// update() of the light table alone (Renderer::set_camera): the lights and light_cdf buffers
  /// from `previous`'s to `lights` and `light_cdf`.
  Upload update_lights(const cl_util::Context& ctx, const PackedScene& previous,
                       const std::vector<lc_light>& lights, const std::vector<float>& light_cdf);

  /// Sets kernel arguments first .. first + kArgCount - 1; returns the next argument index.
  int set_args(cl::Kernel& kernel, int first = 0) const;
};

/// A CPU device's scene buffers of kHugePageMinBuffer bytes or more live in host blocks of whole
/// huge pages (device_scene.cpp); host_block_bytes() is the host memory a buffer of `bytes` then
/// takes on such a device.
constexpr std::size_t kHugePageBytes = std::size_t(2) << 20;
constexpr std::size_t kHugePageMinBuffer = std::size_t(1) << 20;
std::uint64_t host_block_bytes(std::uint64_t bytes);

/// A read-only buffer holding `bytes` (at least 1) of `data`, copied at creation: in a huge-page
/// block on a CPU device when it is that large, else copied by OpenCL (CL_MEM_COPY_HOST_PTR).
/// The scene's buffers, and the traversal test and benchmark's (tests/support/device_tracer.cpp).
cl::Buffer read_only_buffer(const cl_util::Context& ctx, const void* data, std::size_t bytes);

/// Host blocks in huge pages that scene buffers of CPU devices use now (device_scene.cpp): each
/// is freed when its buffer is deleted. For tests.
int huge_page_blocks();

}  // namespace lucent::render_detail
