#include "render/device_scene.hpp"

#include <algorithm>

namespace lucent::render_detail {

namespace {

template <typename T>
cl::Buffer make_buffer(const cl_util::Context& ctx, const std::vector<T>& v) {
  // OpenCL forbids empty buffers: keep one (zeroed) element
  size_t bytes = std::max<size_t>(1, v.size()) * sizeof(T);
  cl::Buffer b(ctx.context, CL_MEM_READ_ONLY, bytes);
  if (!v.empty()) ctx.queue.enqueueWriteBuffer(b, CL_FALSE, 0, v.size() * sizeof(T), v.data());
  return b;
}

}  // namespace

DeviceScene::DeviceScene(const cl_util::Context& ctx, const PackedScene& p)
    : params(make_buffer(ctx, std::vector<lc_params>{p.params})),
      nodes(make_buffer(ctx, p.bvh.nodes)),
      prim_refs(make_buffer(ctx, p.bvh.prim_refs)),
      triangles(make_buffer(ctx, p.triangles)),
      tri_attrs(make_buffer(ctx, p.tri_attrs)),
      spheres(make_buffer(ctx, p.spheres)),
      materials(make_buffer(ctx, p.materials)),
      lights(make_buffer(ctx, p.lights)),
      light_cdf(make_buffer(ctx, p.light_cdf)),
      textures(make_buffer(ctx, p.textures)),
      texels(make_buffer(ctx, p.texels)) {}

int DeviceScene::set_args(cl::Kernel& kernel, int arg) const {
  for (const cl::Buffer* b : {&params, &nodes, &prim_refs, &triangles, &tri_attrs, &spheres, &materials,
                              &lights, &light_cdf, &textures, &texels})
    kernel.setArg(arg++, *b);
  return arg;
}

}  // namespace lucent::render_detail
