#include "support/device_tracer.hpp"

#include <chrono>

#include "cl/kernel_source.hpp"
#include "cl/program_cache.hpp"
#include "lucent/error.hpp"
#include "render/device_scene.hpp"
#include "render/features.hpp"

namespace lucent::bvh {

namespace {

template <class T, class A>
cl::Buffer upload(const cl_util::Context& ctx, const std::vector<T, A>& v) {
  // made as the renderer's (on a CPU device, when large, over the array's host block or a copy
  // in a new one, render/device_scene.cpp); OpenCL refuses empty buffers: keep one zeroed element
  const T zero{};
  return v.empty() ? render_detail::read_only_buffer(ctx, &zero, sizeof(T))
                   : render_detail::read_only_buffer(ctx, v.data(), v.size() * sizeof(T));
}

}  // namespace

DeviceTracer::DeviceTracer(const cl_util::Context& ctx, const std::vector<lc_triangle>& triangles,
                           const std::vector<lc_sphere>& spheres, const Bvh& bvh,
                           const std::string& build_options, const std::string& cache_dir,
                           const std::string& kernel_dir, bool device_defines)
    : ctx_(ctx) {
  program_ = cl_util::build_program_cached(
      ctx, detail::assemble_kernel_source("test/trace_rays.cl", kernel_dir),
      "-cl-std=CL1.2" +
          (device_defines ? render_detail::device_defines(ctx.device.info) : std::string()) +
          (build_options.empty() ? "" : " " + build_options),
      cache_dir);
  try {
    kernel_ = cl::Kernel(program_, "lucent_trace_rays");
    lc_params p{};
    p.num_triangles = static_cast<lc_uint>(triangles.size());
    p.num_spheres = static_cast<lc_uint>(spheres.size());
    p.num_nodes = static_cast<lc_uint>(bvh.nodes.size());
    params_ = upload(ctx, std::vector<lc_params>{p});
    nodes_ = upload(ctx, bvh.nodes);
    leaves_ = upload(ctx, bvh.leaves);
    tris_ = upload(ctx, triangles);
    spheres_ = upload(ctx, spheres);
  } catch (const cl::Error& e) {
    throw Error(cl_util::describe(e));
  }
}

std::vector<TraceHit> DeviceTracer::trace(const std::vector<TraceRay>& rays, bool any_hit) {
  std::vector<TraceHit> hits(rays.size());
  if (rays.empty()) return hits;
  try {
    cl::Buffer rb(ctx_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                  rays.size() * sizeof(TraceRay), const_cast<TraceRay*>(rays.data()));
    cl::Buffer hb(ctx_.context, CL_MEM_WRITE_ONLY, hits.size() * sizeof(TraceHit));
    int a = 0;
    for (cl::Buffer* b : {&params_, &nodes_, &leaves_, &tris_, &spheres_, &rb, &hb})
      kernel_.setArg(a++, *b);
    kernel_.setArg(a++, static_cast<cl_uint>(rays.size()));
    kernel_.setArg(a++, static_cast<cl_uint>(any_hit ? 1 : 0));
    ctx_.queue.finish();
    auto t0 = std::chrono::steady_clock::now();
    // work-groups of 64, as the renderer's (the kernel skips the items past `count`): PoCL
    // compiles a work-group function per local size, and left to choose it follows the number
    // of rays (nine functions of this kernel over the suite)
    const size_t global = (rays.size() + 63) / 64 * 64;
    ctx_.queue.enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange(global), cl::NDRange(64));
    ctx_.queue.finish();
    kernel_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ctx_.queue.enqueueReadBuffer(hb, CL_TRUE, 0, hits.size() * sizeof(TraceHit), hits.data());
  } catch (const cl::Error& e) {
    throw Error(cl_util::describe(e));
  }
  return hits;
}

bool DeviceTracer::mask_intrinsics() {
  try {
    cl::Kernel k(program_, "lucent_trace_info");
    cl::Buffer b(ctx_.context, CL_MEM_WRITE_ONLY, sizeof(cl_int));
    k.setArg(0, b);
    ctx_.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1), cl::NDRange(1));
    cl_int v = -1;
    ctx_.queue.enqueueReadBuffer(b, CL_TRUE, 0, sizeof v, &v);
    return v == 1;
  } catch (const cl::Error& e) {
    throw Error(cl_util::describe(e));
  }
}

}  // namespace lucent::bvh
