// The kernel renderer: packs the scene into OpenCL buffers, builds the megakernel for the
// scene's features and launches progressive passes, accumulating in double on the host.
#include <algorithm>
#include <chrono>
#include <cmath>

#include <unistd.h>

#include "cl/context.hpp"
#include "cl/kernel_source.hpp"
#include "cl/program_cache.hpp"
#include "lucent/error.hpp"
#include "lucent/render.hpp"
#include "render/device_scene.hpp"
#include "render/pack.hpp"

namespace lucent {

namespace {

constexpr size_t kWorkGroupSize = 64;  // fixed: each new size costs PoCL a work-group compile

}  // namespace

RenderResult render(const Scene& scene, const RenderOptions& options) {
  using clock = std::chrono::steady_clock;
  const int width = scene.film.width, height = scene.film.height;
  const size_t npix = static_cast<size_t>(width) * height;
  // host: double sums, sums of squares and counts, the pass read-back and the two result images
  const double host_bytes = double(npix) * (6 * sizeof(double) + sizeof(std::uint32_t) +
                                            2 * sizeof(cl_float4) + 6 * sizeof(float));
  const double host_memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGESIZE));
  if (host_memory > 0 && host_bytes > 0.8 * host_memory)
    throw Error(scene.path + ": a " + std::to_string(width) + "x" + std::to_string(height) +
                " film needs " + std::to_string(static_cast<long long>(host_bytes / (1 << 20))) +
                " MiB of host memory; this machine has " +
                std::to_string(static_cast<long long>(host_memory / (1 << 20))) + " MiB");
  render_detail::PackedScene packed = render_detail::pack_scene(scene);
  cl_util::Context ctx(options.device);
  RenderResult result;
  result.device = ctx.device.info.name;
  render_detail::check_precision_support(ctx.device.info, options.precision);
  const cl_ulong max_alloc = ctx.device.device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  if (npix * sizeof(cl_float4) > max_alloc)
    throw Error(scene.path + ": a " + std::to_string(width) + "x" + std::to_string(height) +
                " film needs a " + std::to_string(npix * sizeof(cl_float4) >> 20) +
                " MiB buffer; the device allows " + std::to_string(max_alloc >> 20) + " MiB per buffer");
  const std::uint64_t target_spp =
      options.spp > 0 ? static_cast<std::uint64_t>(options.spp)
                      : (options.time_limit > 0 ? 0 : static_cast<std::uint64_t>(scene.integrator.spp));

  auto tb = clock::now();
  std::string source = detail::assemble_kernel_source("megakernel.cl");
  std::string build_options = render_detail::build_options(scene, packed, options);
  cl_util::ProgramBuildInfo build_info;
  cl::Program program = cl_util::build_program_cached(ctx, source, build_options, &build_info);
  result.build_seconds = std::chrono::duration<double>(clock::now() - tb).count();
  result.program_cache_hit = build_info.cache_hit;
  result.build_options = build_options;

  std::vector<double> sum(npix * 3, 0.0), sumsq(npix * 3, 0.0);
  std::vector<std::uint32_t> count(npix, 0);
  try {
    cl::Kernel kernel(program, "lucent_render");
    cl::CommandQueue& q = ctx.queue;
    render_detail::DeviceScene dev(ctx, packed);
    cl::Buffer b_sum(ctx.context, CL_MEM_WRITE_ONLY, npix * sizeof(cl_float4));
    cl::Buffer b_sumsq(ctx.context, CL_MEM_WRITE_ONLY, npix * sizeof(cl_float4));
    cl::Buffer b_counters(ctx.context, CL_MEM_READ_WRITE, LC_COUNTER_COUNT * sizeof(lc_uint));
    int arg = dev.set_args(kernel);
    kernel.setArg(arg++, b_sum);
    kernel.setArg(arg++, b_sumsq);
    kernel.setArg(arg++, b_counters);
    cl::Buffer& b_params = dev.params;

    const size_t global = (npix + kWorkGroupSize - 1) / kWorkGroupSize * kWorkGroupSize;
    {
      // Warm-up launch with no samples: some drivers (PoCL) compile the work-group function at
      // the first enqueue; count that as build time, not render time.
      auto tw = clock::now();
      lc_params P0 = packed.params;
      P0.samples_per_pass = 0;
      q.enqueueWriteBuffer(b_params, CL_FALSE, 0, sizeof(P0), &P0);
      q.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global), cl::NDRange(kWorkGroupSize));
      q.finish();
      result.build_seconds += std::chrono::duration<double>(clock::now() - tw).count();
    }
    std::vector<cl_float4> h_sum(npix), h_sumsq(npix);
    std::uint64_t done = 0;
    std::uint32_t pass_spp = 1;
    double render_seconds = 0;
    auto t_start = clock::now();
    for (;;) {
      if (target_spp > 0 && done >= target_spp) break;
      if (options.time_limit > 0 && render_seconds >= options.time_limit && done > 0) break;
      if (options.cancel && options.cancel->load() && done > 0) {
        result.cancelled = true;
        break;
      }
      std::uint32_t n = pass_spp;
      if (target_spp > 0) n = static_cast<std::uint32_t>(std::min<std::uint64_t>(n, target_spp - done));
      lc_params P = packed.params;
      P.sample_offset = static_cast<lc_uint>(done);
      P.samples_per_pass = n;
      lc_uint zero[LC_COUNTER_COUNT] = {0, 0, 0, 0};
      auto tp = clock::now();
      q.enqueueWriteBuffer(b_params, CL_FALSE, 0, sizeof(P), &P);
      q.enqueueWriteBuffer(b_counters, CL_FALSE, 0, sizeof(zero), zero);
      q.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global), cl::NDRange(kWorkGroupSize));
      q.enqueueReadBuffer(b_sum, CL_FALSE, 0, npix * sizeof(cl_float4), h_sum.data());
      q.enqueueReadBuffer(b_sumsq, CL_FALSE, 0, npix * sizeof(cl_float4), h_sumsq.data());
      lc_uint counters[LC_COUNTER_COUNT];
      q.enqueueReadBuffer(b_counters, CL_TRUE, 0, sizeof(counters), counters);
      double pass_time = std::chrono::duration<double>(clock::now() - tp).count();
      render_seconds += pass_time;
      for (size_t i = 0; i < npix; ++i) {
        for (int c = 0; c < 3; ++c) {
          sum[i * 3 + c] += h_sum[i].s[c];
          sumsq[i * 3 + c] += h_sumsq[i].s[c];
        }
        count[i] += static_cast<std::uint32_t>(h_sum[i].s[3]);
      }
      result.nonfinite += counters[LC_COUNTER_NONFINITE];
      result.rays += counters[LC_COUNTER_RAYS];
      done += n;
      // next pass: aim at pass_seconds per launch
      double per_spp = pass_time / n;
      double want = per_spp > 0 ? options.pass_seconds / per_spp : 2.0 * n;
      pass_spp = static_cast<std::uint32_t>(std::clamp(want, 1.0, std::min(4.0 * n, 65536.0)));
      if (options.time_limit > 0 && per_spp > 0) {
        double left = options.time_limit - render_seconds;
        pass_spp = static_cast<std::uint32_t>(std::clamp(left / per_spp, 1.0, double(pass_spp)));
      }
      if (options.on_progress) {
        RenderProgress pr;
        pr.samples_done = done;
        pr.samples_target = target_spp;
        pr.elapsed = std::chrono::duration<double>(clock::now() - t_start).count();
        pr.time_limit = options.time_limit;
        pr.samples_per_second = render_seconds > 0 ? double(done) * npix / render_seconds : 0;
        options.on_progress(pr);
      }
    }
    result.spp = done;
    result.seconds = render_seconds;
  } catch (const cl::Error& e) {
    throw Error(cl_util::describe(e));
  }

  result.mean = Image{width, height, std::vector<float>(npix * 3)};
  result.variance = Image{width, height, std::vector<float>(npix * 3)};
  result.samples = count;
  for (size_t i = 0; i < npix; ++i) {
    double n = count[i];
    for (int c = 0; c < 3; ++c) {
      double s = sum[i * 3 + c], s2 = sumsq[i * 3 + c];
      double mean = n > 0 ? s / n : 0;
      double var = n > 1 ? std::max(0.0, (s2 - s * mean) / (n - 1)) : 0;
      result.mean.rgb[i * 3 + c] = static_cast<float>(mean);
      result.variance.rgb[i * 3 + c] = static_cast<float>(var);
    }
  }
  return result;
}

}  // namespace lucent
