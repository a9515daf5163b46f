#include "render/device_scene.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "render/resources.hpp"

namespace lucent::render_detail {

namespace {

// Huge pages for a CPU device's large scene buffers. A CPU device's buffers are host memory, and
// every ray reads the BVH's nodes and leaf blocks (and the triangles, textures) at random: over
// megabytes of 4 KiB pages most of those reads miss the TLB as well. A buffer of kHugePageMinBuffer
// bytes or more therefore lives in a block aligned to 2 MiB and advised as transparent huge pages
// (Linux's MADV_HUGEPAGE: used when /sys/kernel/mm/transparent_hugepage/enabled says "madvise",
// Debian's default, or "always"; ordinary pages otherwise), given to OpenCL with
// CL_MEM_USE_HOST_PTR and freed by the buffer's destructor callback. Dragon box (12 MiB of
// triangles, 6 MiB of tree): about 1.05x the samples per second (BENCHMARKS.md). GPUs keep
// copied buffers. LUCENT_HUGE_PAGES=0 turns this off.
std::atomic<int> g_huge_blocks{0};

void CL_CALLBACK free_huge_block(cl_mem, void* block) {
  std::free(block);
  g_huge_blocks.fetch_sub(1);
}

bool huge_pages_wanted() {
  const char* e = std::getenv("LUCENT_HUGE_PAGES");
  return !(e && std::strcmp(e, "0") == 0);
}

/// `bytes` of `data` in a buffer over a huge-page block; a null buffer where no such block could
/// be made (the caller then copies as usual).
cl::Buffer huge_page_buffer(const cl_util::Context& ctx, const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const std::size_t size = host_block_bytes(bytes);
  void* block = std::aligned_alloc(kHugePageBytes, size);
  if (!block) return cl::Buffer();
  madvise(block, size, MADV_HUGEPAGE);  // advice: refused, the block keeps ordinary pages
  std::memcpy(block, data, bytes);
  cl_int err = CL_SUCCESS;
  cl_mem mem =
      clCreateBuffer(ctx.context(), CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, bytes, block, &err);
  if (err != CL_SUCCESS) {
    std::free(block);
    return cl::Buffer();
  }
  if (clSetMemObjectDestructorCallback(mem, free_huge_block, block) != CL_SUCCESS) {
    // no command has used the buffer: releasing it deletes it, and the block is ours again
    clReleaseMemObject(mem);
    std::free(block);
    return cl::Buffer();
  }
  g_huge_blocks.fetch_add(1);
  return cl::Buffer(mem);  // takes the reference clCreateBuffer returned
#else
  (void)ctx;
  (void)data;
  (void)bytes;
  return cl::Buffer();
#endif
}

template <typename T>
cl::Buffer make_buffer(const cl_util::Context& ctx, const std::vector<T>& v) {
  // OpenCL forbids empty buffers: keep one element
  if (v.empty()) return cl::Buffer(ctx.context, CL_MEM_READ_ONLY, sizeof(T));
  return read_only_buffer(ctx, v.data(), v.size() * sizeof(T));
}

template <typename T>
void update_buffer(const cl_util::Context& ctx, cl::Buffer& buffer, const std::vector<T>& old,
                   const std::vector<T>& now, DeviceScene::Upload& up) {
  if (old.size() == now.size() &&
      (now.empty() || std::memcmp(old.data(), now.data(), now.size() * sizeof(T)) == 0))
    return;
  if (old.size() != now.size() || now.empty()) {
    buffer = make_buffer(ctx, now);
  } else {
    ctx.queue.enqueueWriteBuffer(buffer, CL_TRUE, 0, now.size() * sizeof(T), now.data());
  }
  ++up.buffers;
  up.bytes += now.size() * sizeof(T);
}

}  // namespace

cl::Buffer read_only_buffer(const cl_util::Context& ctx, const void* data, std::size_t bytes) {
  // The data is copied when the buffer is created (CL_MEM_COPY_HOST_PTR, or into the huge-page
  // block), so it may be a temporary: an asynchronous write from it would read freed memory
  // (AddressSanitizer caught exactly that).
  if (bytes >= kHugePageMinBuffer && buffers_in_host_memory(ctx.device.device) &&
      huge_pages_wanted()) {
    cl::Buffer b = huge_page_buffer(ctx, data, bytes);
    if (b() != nullptr) return b;
  }
  return cl::Buffer(ctx.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes,
                    const_cast<void*>(data));
}

int huge_page_blocks() { return g_huge_blocks.load(); }

std::uint64_t host_block_bytes(std::uint64_t bytes) {
  if (bytes < kHugePageMinBuffer) return bytes;
  return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
}

DeviceScene::Upload DeviceScene::update(const cl_util::Context& ctx, const PackedScene& previous,
                                        const PackedScene& packed) {
  Upload up;
#define LUCENT_UPDATE(name, type, ...) update_buffer(ctx, name, previous.name, packed.name, up);
  LC_SCENE_BUFFERS(LUCENT_UPDATE)
#undef LUCENT_UPDATE
  return up;
}

DeviceScene::Upload DeviceScene::update_lights(const cl_util::Context& ctx,
                                               const PackedScene& previous,
                                               const std::vector<lc_light>& now_lights,
                                               const std::vector<float>& now_cdf) {
  Upload up;
  update_buffer(ctx, lights, previous.lights, now_lights, up);
  update_buffer(ctx, light_cdf, previous.light_cdf, now_cdf, up);
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
