#include "render/device_scene.hpp"

#include <algorithm>
#include <cstring>

#include "render/resources.hpp"

namespace lucent::render_detail {

namespace {

// Huge pages and one copy for a CPU device's large scene buffers (core/host_blocks.hpp): a buffer
// of kHugePageMinBuffer bytes or more is made with CL_MEM_USE_HOST_PTR over a host block, the
// packed array's own where it is one (the session's PackedScene arrays are sys::HostVectors), and
// holds a reference to that block until the driver deletes the buffer (its destructor callback).
// GPUs keep copied buffers.

void CL_CALLBACK release_block(cl_mem, void* block) { sys::release_host_block(block); }

/// `bytes` of `data` in a buffer over a host block (data's own, or a new one holding a copy); a
/// null buffer where none could be made (the caller then copies as usual).
cl::Buffer block_buffer(const cl_util::Context& ctx, const void* data, std::size_t bytes) {
  void* block = const_cast<void*>(data);  // read-only: the buffer is CL_MEM_READ_ONLY
  if (!sys::retain_host_block(data, bytes)) {
    block = sys::allocate_host_block(bytes);
    if (!block) return cl::Buffer();
    std::memcpy(block, data, bytes);
  }
  // from here we hold one reference to `block`, which the buffer takes over
  cl_int err = CL_SUCCESS;
  cl_mem mem =
      clCreateBuffer(ctx.context(), CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, bytes, block, &err);
  if (err != CL_SUCCESS) {
    sys::release_host_block(block);
    return cl::Buffer();
  }
  if (clSetMemObjectDestructorCallback(mem, release_block, block) != CL_SUCCESS) {
    // no command has used the buffer: releasing it deletes it, and the block is no longer read
    clReleaseMemObject(mem);
    sys::release_host_block(block);
    return cl::Buffer();
  }
  return cl::Buffer(mem);  // takes the reference clCreateBuffer returned
}

template <typename T, typename A>
cl::Buffer make_buffer(const cl_util::Context& ctx, const std::vector<T, A>& v) {
  // OpenCL forbids empty buffers: keep one element
  if (v.empty()) return cl::Buffer(ctx.context, CL_MEM_READ_ONLY, sizeof(T));
  return read_only_buffer(ctx, v.data(), v.size() * sizeof(T));
}

template <typename T, typename A>
bool same_contents(const std::vector<T, A>& a, const std::vector<T, A>& b) {
  return a.size() == b.size() && (a.empty() || a.data() == b.data() ||
                                  std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

template <typename T, typename A>
void update_buffer(const cl_util::Context& ctx, bool host, cl::Buffer& buffer, bool changed,
                   const std::vector<T, A>& now, DeviceScene::Upload& up) {
  if (!changed) return;
  // the size changed, or the device reads host memory: a new buffer (on a CPU device over the
  // array's block where it is large; writing in place would write into the block the previous
  // packing's array and the other devices' buffers share). Else written in place.
  if (host || now.empty() || buffer.getInfo<CL_MEM_SIZE>() != now.size() * sizeof(T)) {
    buffer = make_buffer(ctx, now);
  } else {
    ctx.queue.enqueueWriteBuffer(buffer, CL_TRUE, 0, now.size() * sizeof(T), now.data());
  }
  ++up.buffers;
  up.bytes += now.size() * sizeof(T);
}

}  // namespace

cl::Buffer read_only_buffer(const cl_util::Context& ctx, const void* data, std::size_t bytes) {
  // Otherwise the data is copied when the buffer is created (CL_MEM_COPY_HOST_PTR), so it may be
  // a temporary: an asynchronous write from it would read freed memory (AddressSanitizer caught
  // exactly that).
  if (bytes >= kHugePageMinBuffer && buffers_in_host_memory(ctx.device.device)) {
    cl::Buffer b = block_buffer(ctx, data, bytes);
    if (b() != nullptr) return b;
  }
  return cl::Buffer(ctx.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes,
                    const_cast<void*>(data));
}

int huge_page_blocks() { return sys::host_blocks(); }

unsigned scene_changes(const PackedScene& a, const PackedScene& b) {
  unsigned changes = 0;
#define LUCENT_CHANGED(name, type, ...) \
  if (!same_contents(a.name, b.name)) changes |= kBufferBit(name##_index);
  LC_SCENE_BUFFERS(LUCENT_CHANGED)
#undef LUCENT_CHANGED
  return changes;
}

unsigned light_changes(const PackedScene& packed, const sys::HostVector<lc_light>& lights,
                       const sys::HostVector<float>& light_cdf) {
  return (same_contents(packed.lights, lights) ? 0u : kBufferBit(lights_index)) |
         (same_contents(packed.light_cdf, light_cdf) ? 0u : kBufferBit(light_cdf_index));
}

void keep_unchanged_storage(PackedScene& previous, PackedScene& next, unsigned changes) {
#define LUCENT_KEEP(name, type, ...) \
  if (!(changes & kBufferBit(name##_index))) previous.name.swap(next.name);
  LC_SCENE_BUFFERS(LUCENT_KEEP)
#undef LUCENT_KEEP
}

DeviceScene::Upload DeviceScene::update(const cl_util::Context& ctx, unsigned changes,
                                        const PackedScene& packed) {
  Upload up;
  const bool host = buffers_in_host_memory(ctx.device.device);
#define LUCENT_UPDATE(name, type, ...) \
  update_buffer(ctx, host, name, (changes & kBufferBit(name##_index)) != 0, packed.name, up);
  LC_SCENE_BUFFERS(LUCENT_UPDATE)
#undef LUCENT_UPDATE
  return up;
}

DeviceScene::Upload DeviceScene::update_lights(const cl_util::Context& ctx, unsigned changes,
                                               const sys::HostVector<lc_light>& now_lights,
                                               const sys::HostVector<float>& now_cdf) {
  Upload up;
  const bool host = buffers_in_host_memory(ctx.device.device);
  update_buffer(ctx, host, lights, (changes & kBufferBit(lights_index)) != 0, now_lights, up);
  update_buffer(ctx, host, light_cdf, (changes & kBufferBit(light_cdf_index)) != 0, now_cdf, up);
  return up;
}

DeviceScene::DeviceScene(const cl_util::Context& ctx, const PackedScene& p)
    :
#define LUCENT_UPLOAD(name, type, ...) name(make_buffer(ctx, p.name)),
      LC_SCENE_BUFFERS(LUCENT_UPLOAD)
#undef LUCENT_UPLOAD
          params(make_buffer(ctx, std::vector<lc_params>{p.params})) {
}

int DeviceScene::set_args(cl::Kernel& kernel, int arg) const {
#define LUCENT_SET_ARG(name, type, ...) kernel.setArg(arg++, name);
  LC_SCENE_BUFFERS(LUCENT_SET_ARG)
#undef LUCENT_SET_ARG
  kernel.setArg(arg++, params);
  return arg;
}

}  // namespace lucent::render_detail
