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

  /// Creates the buffers with their contents: on a CPU device a large array's buffer is made over
  /// its host block, which it shares (read_only_buffer), else they are copied at creation.
  DeviceScene(const cl_util::Context& ctx, const PackedScene& packed);

  struct Upload {
    int buffers = 0;        ///< buffers written
    std::size_t bytes = 0;  ///< bytes written
  };
  /// Brings the buffers from what they hold to `packed`, where `changes` (scene_changes of the
  /// packing they hold and `packed`) says which differ: on a CPU device a changed buffer is made
  /// again (over `packed`'s block where it is large: a buffer that shares a block is never written,
  /// as the block belongs to the arrays too), elsewhere rewritten in place where its size stayed.
  /// The kernel arguments must be set again after.
  Upload update(const cl_util::Context& ctx, unsigned changes, const PackedScene& packed);

  /// update() of the light table alone (Renderer::set_camera): `changes` (scene_changes of the
  /// packing and one with `lights` and `light_cdf` in place of its own) names those two at most.
  Upload update_lights(const cl_util::Context& ctx, unsigned changes,
                       const sys::HostVector<lc_light>& lights,
                       const sys::HostVector<float>& light_cdf);

  /// Sets kernel arguments first .. first + kArgCount - 1; returns the next argument index.
  int set_args(cl::Kernel& kernel, int first = 0) const;
};

/// The buffers (by their bit, 1 << index in LC_SCENE_BUFFERS: kBufferBit) whose contents differ
/// between two packings.
#define LUCENT_BUFFER_INDEX(name, type, ...) name##_index,
enum SceneBufferIndex { LC_SCENE_BUFFERS(LUCENT_BUFFER_INDEX) kSceneBufferCount };
#undef LUCENT_BUFFER_INDEX
constexpr unsigned kBufferBit(SceneBufferIndex i) { return 1u << i; }
unsigned scene_changes(const PackedScene& a, const PackedScene& b);
/// scene_changes of `packed` and `packed` with `lights` and `light_cdf` in place of its own.
unsigned light_changes(const PackedScene& packed, const sys::HostVector<lc_light>& lights,
                       const sys::HostVector<float>& light_cdf);

/// After every device took `next` (DeviceScene::update with `changes` = scene_changes(previous,
/// next)): each array that did not change goes back to the storage it had in `previous`, which
/// the CPU devices' buffers kept and share, and `previous` takes `next`'s equal copy, so that the
/// session holds one copy of each array once `previous` is replaced by `next`.
void keep_unchanged_storage(PackedScene& previous, PackedScene& next, unsigned changes);

/// A CPU device's scene buffers of kHugePageMinBuffer bytes or more live in host blocks of whole
/// huge pages (core/host_blocks.hpp); host_block_bytes() is the host memory such an array takes.
using sys::host_block_bytes;
using sys::kHugePageBytes;
using sys::kHugePageMinBuffer;

/// A read-only buffer holding `bytes` (at least 1) of `data`. On a CPU device, from
/// kHugePageMinBuffer bytes: where `data` is the start of a host block (a sys::HostVector's
/// storage) a buffer over that block, which it holds (no copy: the block must not be written
/// while the buffer lives), else over a new block holding a copy. Otherwise copied by OpenCL at
/// creation (CL_MEM_COPY_HOST_PTR). The scene's buffers, and the traversal test and benchmark's
/// (tests/support/device_tracer.cpp).
cl::Buffer read_only_buffer(const cl_util::Context& ctx, const void* data, std::size_t bytes);

/// Host blocks alive now (sys::host_blocks: the packed arrays' and the buffers' they share; each
/// is freed with the last of them). For tests.
int huge_page_blocks();

}  // namespace lucent::render_detail
