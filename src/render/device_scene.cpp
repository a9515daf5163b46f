#include "render/device_scene.hpp"

#include <algorithm>
#include <cstring>

namespace lucent::render_detail {

namespace {

template <typename T>
cl::Buffer make_buffer(const cl_util::Context& ctx, const std::vector<T>& v) {
  // OpenCL forbids empty buffers: keep one element. The data is copied when the buffer is
  // created (CL_MEM_COPY_HOST_PTR), so `v` may be a temporary: an asynchronous write from it
  // would read freed memory (AddressSanitizer caught exactly that).
  if (v.empty()) return cl::Buffer(ctx.context, CL_MEM_READ_ONLY, sizeof(T));
  return cl::Buffer(ctx.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(T),
                    const_cast<T*>(v.data()));
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

DeviceScene::Upload DeviceScene::update(const cl_util::Context& ctx, const PackedScene& previous,
                                        const PackedScene& packed) {
  Upload up;
#define LUCENT_UPDATE(name, type, ...) update_buffer(ctx, name, previous.name, packed.name, up);
  LC_SCENE_BUFFERS(LUCENT_UPDATE)
#undef LUCENT_UPDATE
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
