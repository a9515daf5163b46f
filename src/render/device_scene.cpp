#include "render/device_scene.hpp"

#include <algorithm>

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

}  // namespace

DeviceScene::DeviceScene(const cl_util::Context& ctx, const PackedScene& p)
    : params(make_buffer(ctx, std::vector<lc_params>{p.params})),
      nodes(make_buffer(ctx, p.bvh.nodes)),
      leaves(make_buffer(ctx, p.bvh.leaves)),
      triangles(make_buffer(ctx, p.triangles)),
      tri_attrs(make_buffer(ctx, p.tri_attrs)),
      spheres(make_buffer(ctx, p.spheres)),
      materials(make_buffer(ctx, p.materials)),
      lights(make_buffer(ctx, p.lights)),
      light_cdf(make_buffer(ctx, p.light_cdf)),
      textures(make_buffer(ctx, p.textures)),
      texels(make_buffer(ctx, p.texels)) {}

int DeviceScene::set_args(cl::Kernel& kernel, int arg) const {
  for (const cl::Buffer* b : {&params, &nodes, &leaves, &triangles, &tri_attrs, &spheres, &materials,
                              &lights, &light_cdf, &textures, &texels})
    kernel.setArg(arg++, *b);
  return arg;
}

}  // namespace lucent::render_detail
