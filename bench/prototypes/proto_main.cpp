// lucent_proto: design prototypes for issue 11 (SIMD width on CPU devices); not part of the
// renderer and not a test. On one scene (diffuse triangles and triangle lights for every mode
// but mega and wave), in alternating rounds, with --modes (comma-separated):
//   mega    the renderer's megakernel (kernels/megakernel.cl), one launch of --spp samples per
//           pixel (its fastest case: no per-pass host work), local size --local;
//   wave    bench/prototypes/wavefront.cl: the same integrator split into stages over a
//           structure-of-arrays path state (generate, then max_depth x (trace, shade, shadow),
//           then film), one path per pixel per wave, --spp waves; per-stage times;
//   vwave   the same with wf_generate_vec and wf_shade_vec (written for PoCL's vectoriser);
//   pwave   the same with wf_generate_vec and wf_shade_pk (--pk paths per work-item in lanes);
//   pkmega  the packet megakernel pk_mega (--pk paths per work-item for the whole path loop);
//   packet  closest-hit traversal of the rays of waves 0..2 (primary, first and second bounce),
//           one ray per work-item (the renderer's bvh_trace) against --packet rays per work-item
//           (packet_trace): hit agreement and Mrays;
//   micro   micro-kernels: what PoCL's vectoriser accepts (with POCL_VECTORIZER_REMARKS=1 its
//           remarks follow each "=== first launch" line on stdout).
// --packet-rays: the wave modes and pkmega trace closest-hit and shadow rays by packet_trace,
// --packet rays at a time (pkmega: --packet must equal --pk). The image means of mega and of
// each other mode (and their largest per-pixel difference) are printed. Times are the process's
// CPU seconds (all threads; a loaded machine disturbs them far less than wall time), --wall for
// wall clock. Other options: --width --height --spp --reps --wave-local N --fast-math
// --extra BUILD_OPTIONS. Build: cmake --build build --target lucent_proto (not part of the
// default build). Written against the host code and kernels of commit f227b8a, before issue 10's
// refactor (registries, one kernel file per type, the scene buffers' argument order): on later
// commits wavefront.cl's includes and stage argument lists, and build_options here, need porting.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cl/context.hpp"
#include "cl/kernel_source.hpp"
#include "lucent/error.hpp"
#include "lucent/render.hpp"
#include "lucent/scene.hpp"
#include "render/device_scene.hpp"
#include "render/pack.hpp"

namespace {

using namespace lucent;
using clk = std::chrono::steady_clock;
// Process CPU time (user + system, every thread): the stages run on PoCL's worker threads, and
// on a loaded machine their CPU time varies much less than the wall time.
double cpu_now() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}
struct Tick {  // wall or CPU seconds since construction (--wall)
  clk::time_point w = clk::now();
  double c = cpu_now();
};
bool g_wall = false;
double since(const Tick& t) {
  return g_wall ? std::chrono::duration<double>(clk::now() - t.w).count() : cpu_now() - t.c;
}

constexpr int kFloatComps = 29, kUintComps = 2;  // S_COUNT, U_COUNT of wavefront.cl
constexpr int kHT = 16, kPrim = 1, kFlags = 0;   // S_HT, U_PRIM, U_FLAGS

struct Options {
  std::string scene;
  int width = 256, height = 256, spp = 16, reps = 3, local = 64, wave_local = 64, packet = 16,
      pk = 8;
  std::string modes = "mega,wave,packet", extra;
  bool fast_math = false, packet_rays = false;
};

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw Error(path + ": cannot read");
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

struct Means {
  double m[3] = {0, 0, 0};
  std::vector<float> px;
};

Means means_of(const std::vector<cl_float4>& sum) {
  Means r;
  r.px.resize(sum.size() * 3);
  for (size_t i = 0; i < sum.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      double v = sum[i].s[3] > 0 ? sum[i].s[c] / sum[i].s[3] : 0.0;
      r.px[i * 3 + c] = float(v);
      r.m[c] += v / double(sum.size());
    }
  return r;
}

int run(const Options& o) {
  Scene scene = load_scene(o.scene);
  scene.film.width = o.width;
  scene.film.height = o.height;
  render_detail::PackedScene packed = render_detail::pack_scene(scene);
  cl_util::Context ctx("");
  RenderOptions ropt;
  ropt.fast_math = o.fast_math;
  std::string opts = render_detail::build_options(scene, packed, ropt) + " " + o.extra;
  const char* kdir_env = std::getenv("LUCENT_KERNEL_DIR");
  std::string kdir = kdir_env && *kdir_env ? kdir_env : LUCENT_PROTO_KERNEL_DIR;
  int cdf_iters = 0;
  while ((1u << cdf_iters) < packed.params.num_lights) ++cdf_iters;
  std::string wopts =
      opts + " -I " + kdir + " -D WF_PACKET=" + std::to_string(o.packet) +
      " -D WF_CDF_ITERS=" + std::to_string(cdf_iters) + " -D WF_PK=" + std::to_string(o.pk) +
      (o.packet_rays ? " -D WF_PK_PACKET_RAYS" : "") +
      // more build options for the prototypes' kernels (wavefront.cl: WF_PD, ...)
      (std::getenv("LUCENT_PROTO_DEFINES") ? std::string(" ") + std::getenv("LUCENT_PROTO_DEFINES")
                                           : std::string());
  std::printf("scene %s, %dx%d, %d spp, max_depth %d, device %s\nbuild options: %s\ntimes: %s\n",
              o.scene.c_str(), o.width, o.height, o.spp, scene.integrator.max_depth,
              ctx.device.info.name.c_str(), wopts.c_str(),
              g_wall ? "wall clock" : "process CPU seconds (all threads; --wall for wall clock)");

  Tick tb;
  cl::Program mega =
      cl_util::build_program(ctx, detail::assemble_kernel_source("megakernel.cl"), opts);
  double mega_build = since(tb);
  tb = Tick();
  cl::Program wave =
      cl_util::build_program(ctx, read_file(LUCENT_PROTO_DIR "/wavefront.cl"), wopts);
  double wave_build = since(tb);
  std::printf("clBuildProgram: megakernel %.2f s, wavefront %.2f s\n", mega_build, wave_build);

  render_detail::DeviceScene dev(ctx, packed);
  cl::CommandQueue& q = ctx.queue;
  const uint32_t npix = uint32_t(o.width) * o.height;
  auto round_up = [](size_t n, size_t l) { return (n + l - 1) / l * l; };

  // megakernel
  cl::Kernel mk(mega, "lucent_render");
  cl::Buffer m_sum(ctx.context, CL_MEM_READ_WRITE, npix * sizeof(cl_float4));
  cl::Buffer m_sumsq(ctx.context, CL_MEM_READ_WRITE, npix * sizeof(cl_float4));
  cl::Buffer m_cnt(ctx.context, CL_MEM_READ_WRITE, 4 * sizeof(cl_uint));
  int a = dev.set_args(mk);
  mk.setArg(a++, m_sum);
  mk.setArg(a++, m_sumsq);
  mk.setArg(a++, m_cnt);
  auto mega_run = [&](uint32_t spp) {
    lc_params P = packed.params;
    P.sample_offset = 0;
    P.samples_per_pass = spp;
    cl_uint zero[4] = {0, 0, 0, 0};
    q.enqueueWriteBuffer(dev.params, CL_TRUE, 0, sizeof(P), &P);
    q.enqueueWriteBuffer(m_cnt, CL_TRUE, 0, sizeof(zero), zero);
    Tick t;
    q.enqueueNDRangeKernel(mk, cl::NullRange, cl::NDRange(round_up(npix, o.local)),
                           cl::NDRange(o.local));
    q.finish();
    double s = since(t);
    cl_uint cnt[4];
    q.enqueueReadBuffer(m_cnt, CL_TRUE, 0, sizeof(cnt), cnt);
    return std::make_pair(s, cnt[1]);
  };

  // wavefront
  cl::Buffer st(ctx.context, CL_MEM_READ_WRITE, size_t(kFloatComps) * npix * sizeof(float));
  cl::Buffer su(ctx.context, CL_MEM_READ_WRITE, size_t(kUintComps) * npix * sizeof(cl_uint));
  cl::Buffer w_sum(ctx.context, CL_MEM_READ_WRITE, npix * sizeof(cl_float4));
  cl::Buffer w_sumsq(ctx.context, CL_MEM_READ_WRITE, npix * sizeof(cl_float4));
  cl::Kernel kg(wave, "wf_generate"), kt(wave, "wf_trace"), ks(wave, "wf_shade"),
      kw(wave, "wf_shadow"), kf(wave, "wf_film"), kts(wave, "wf_trace_single"),
      ktp(wave, "wf_trace_packet"), kgv(wave, "wf_generate_vec"), ksv(wave, "wf_shade_vec"),
      ksp(wave, "wf_shade_pk"), kwp(wave, "wf_shadow_packet"), kpm(wave, "pk_mega");
  for (cl::Kernel* k : {&kg, &kt, &ks, &kw, &kts, &ktp, &kgv, &ksv, &ksp, &kwp}) {
    int i = dev.set_args(*k);
    k->setArg(i++, st);
    k->setArg(i++, su);
    k->setArg(i++, npix);
  }
  {
    int i = dev.set_args(kpm);
    kpm.setArg(i++, st);
    kpm.setArg(i++, su);
    kpm.setArg(i++, npix);
    kpm.setArg(i++, cl_uint(1));
    kpm.setArg(i++, w_sum);
    kpm.setArg(i++, w_sumsq);
  }
  // packet megakernel: WF_PK paths per work-item for the whole path loop, spp in one launch
  auto pkmega_run = [&](uint32_t spp) {
    std::vector<cl_float4> zero(npix, cl_float4{{0, 0, 0, 0}});
    q.enqueueWriteBuffer(w_sum, CL_TRUE, 0, npix * sizeof(cl_float4), zero.data());
    q.enqueueWriteBuffer(w_sumsq, CL_TRUE, 0, npix * sizeof(cl_float4), zero.data());
    lc_params P = packed.params;
    q.enqueueWriteBuffer(dev.params, CL_TRUE, 0, sizeof(P), &P);
    kpm.setArg(render_detail::DeviceScene::kArgCount + 3, cl_uint(spp));
    Tick t;
    q.enqueueNDRangeKernel(kpm, cl::NullRange, cl::NDRange(round_up(npix / o.pk, 8)),
                           cl::NDRange(8));
    q.finish();
    return since(t);
  };
  kf.setArg(0, st);
  kf.setArg(1, npix);
  kf.setArg(2, w_sum);
  kf.setArg(3, w_sumsq);
  const int gen_sample_arg = render_detail::DeviceScene::kArgCount + 3;
  const cl::NDRange wg(round_up(npix, o.wave_local)), wl(o.wave_local);
  struct StageTimes {
    double gen = 0, trace = 0, shade = 0, shadow = 0, film = 0;
    double total() const { return gen + trace + shade + shadow + film; }
  };
  auto launch = [&](cl::Kernel& k, double& acc, size_t lanes = 1) {
    static std::vector<std::string> seen;  // marks the first launch on stderr, where PoCL prints
    std::string name = k.getInfo<CL_KERNEL_FUNCTION_NAME>();  // its vectoriser remarks
    if (std::find(seen.begin(), seen.end(), name) == seen.end()) {
      seen.push_back(name);
      std::fflush(stdout);
      std::printf("\n=== first launch of %s\n", name.c_str());
      std::fflush(stdout);
    }
    Tick t;
    if (lanes == 1)
      q.enqueueNDRangeKernel(k, cl::NullRange, wg, wl);
    else
      q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(round_up(npix / lanes, 8)),
                             cl::NDRange(8));
    q.finish();
    acc += since(t);
  };
  // kind 0: wf_generate + wf_shade; 1: the _vec stages; 2: wf_generate_vec + wf_shade_pk
  auto wave_run = [&](uint32_t spp, StageTimes& tm, int kind) {
    cl::Kernel& gen = kind ? kgv : kg;
    cl::Kernel& shade = kind == 2 ? ksp : (kind ? ksv : ks);
    const size_t shade_lanes = kind == 2 ? size_t(o.pk) : 1;
    // --packet-rays: closest-hit and shadow rays WF_PACKET at a time (wf_trace_packet,
    // wf_shadow_packet) in place of one per work-item
    cl::Kernel& trace = o.packet_rays ? ktp : kt;
    cl::Kernel& shadow = o.packet_rays ? kwp : kw;
    const size_t ray_lanes = o.packet_rays ? size_t(o.packet) : 1;
    std::vector<cl_float4> zero(npix, cl_float4{{0, 0, 0, 0}});
    q.enqueueWriteBuffer(w_sum, CL_TRUE, 0, npix * sizeof(cl_float4), zero.data());
    q.enqueueWriteBuffer(w_sumsq, CL_TRUE, 0, npix * sizeof(cl_float4), zero.data());
    lc_params P = packed.params;
    q.enqueueWriteBuffer(dev.params, CL_TRUE, 0, sizeof(P), &P);
    for (uint32_t s = 0; s < spp; ++s) {
      gen.setArg(gen_sample_arg, s);
      launch(gen, tm.gen);
      for (int d = 0; d < scene.integrator.max_depth; ++d) {
        launch(trace, tm.trace, ray_lanes);
        shade.setArg(gen_sample_arg, cl_uint(d));
        shade.setArg(gen_sample_arg + 1, s);
        launch(shade, tm.shade, shade_lanes);
        launch(shadow, tm.shadow, ray_lanes);
      }
      launch(kf, tm.film);
    }
  };

  auto read_sum = [&](cl::Buffer& b) {
    std::vector<cl_float4> h(npix);
    q.enqueueReadBuffer(b, CL_TRUE, 0, npix * sizeof(cl_float4), h.data());
    return h;
  };
  auto has_mode = [&](const std::string& m) {
    return ("," + o.modes + ",").find("," + m + ",") != std::string::npos;
  };
  const bool do_mega = has_mode("mega"), do_wave = has_mode("wave"), do_wavevec = has_mode("vwave");
  const bool do_wavepk = has_mode("pwave"), do_pkmega = has_mode("pkmega");
  const bool do_kind[3] = {do_wave, do_wavevec, do_wavepk};
  const char* kind_name[3] = {"wave", "vwave", "pwave"};
  const bool do_packet = has_mode("packet");
  if (has_mode("micro")) {
    // micro-kernels over n floats: CPU seconds per launch (best of --reps) and, on stdout with
    // POCL_VECTORIZER_REMARKS=1, the vectoriser's verdict after each "=== first launch" line
    const uint32_t n = npix * 4;
    std::vector<float> init(size_t(n) * 4);
    for (size_t i = 0; i < init.size(); ++i) init[i] = float(i % 1000) * 1e-3f;
    cl::Buffer x(ctx.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, init.size() * sizeof(float),
                 init.data());
    for (const char* name :
         {"m_axpy", "m_axpy_nocheck", "m_sqrt", "m_sinpi", "m_isfinite", "m_select", "m_rng",
          "m_rng_int", "m_normalize3", "m_normalize3_inline", "m_dot3", "m_cosine_sample",
          "m_normalize3_struct", "m_cosine_sample_struct", "m_wf_film"}) {
      cl::Kernel k(wave, name);
      k.setArg(0, x);
      k.setArg(1, n);
      std::fflush(stdout);
      std::printf("\n=== first launch of %s\n", name);
      std::fflush(stdout);
      double best = 1e30;
      for (int r = 0; r < o.reps + 1; ++r) {
        Tick t;
        q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n), cl::NDRange(o.wave_local));
        q.finish();
        if (r)
          best = std::min(best, since(t));
        else
          std::fflush(stdout);
      }
      std::printf("\nmicro %s: %.3f ns per work-item\n", name, best / n * 1e9);
    }
    return 0;
  }
  const double paths = double(npix) * o.spp;

  // warm-up launches (PoCL compiles each kernel's work-group function at its first launch)
  {
    Tick t;
    std::fflush(stdout);
    std::printf("\n=== first launch of lucent_render\n");
    std::fflush(stdout);
    if (do_mega) mega_run(1);
    double wm = since(t);
    t = Tick();
    StageTimes tm;
    if (do_wave || do_packet) wave_run(1, tm, 0);
    if (do_wavevec) wave_run(1, tm, 1);
    if (do_wavepk) wave_run(1, tm, 2);
    if (do_pkmega) pkmega_run(1);
    std::printf(
        "first launches (work-group function compile included): megakernel %.2f s, wavefront %.2f "
        "s\n",
        wm, since(t));
  }
  for (int r = 0; r < o.reps; ++r) {
    if (do_mega) {
      auto [s, rays] = mega_run(o.spp);
      std::printf("round %d mega: %.3f s, %.3f Mpaths/s, %.2f rays/path\n", r, s, paths / s * 1e-6,
                  rays / paths);
    }
    if (do_pkmega) {
      double t = pkmega_run(o.spp);
      std::printf("round %d pkmega: %.3f s, %.3f Mpaths/s\n", r, t, paths / t * 1e-6);
    }
    for (int v = 0; v < 3; ++v) {
      if (!do_kind[v]) continue;
      StageTimes tm;
      wave_run(o.spp, tm, v);
      double t = tm.total();
      std::printf(
          "round %d %s: %.3f s, %.3f Mpaths/s; generate %.3f, trace %.3f, shade %.3f, shadow %.3f, "
          "film %.3f s\n",
          r, kind_name[v], t, paths / t * 1e-6, tm.gen, tm.trace, tm.shade, tm.shadow, tm.film);
    }
  }
  for (int v = 0; v < 4; ++v) {
    if (!do_mega || !(v == 3 ? do_pkmega : do_kind[v])) continue;
    StageTimes tm;
    if (v == 3)
      pkmega_run(o.spp);
    else
      wave_run(o.spp, tm, v);
    mega_run(o.spp);
    Means mm = means_of(read_sum(m_sum));
    Means wm = means_of(read_sum(w_sum));
    double maxd = 0;
    size_t ndiff = 0;
    for (size_t i = 0; i < mm.px.size(); ++i) {
      double d = std::fabs(double(mm.px[i]) - wm.px[i]);
      maxd = std::max(maxd, d);
      ndiff += d > 0;
    }
    std::printf(
        "image means: mega %.5f %.5f %.5f, %s %.5f %.5f %.5f; pixel channels differing %zu of %zu, "
        "max |diff| %.3g\n",
        mm.m[0], mm.m[1], mm.m[2], v == 3 ? "pkmega" : kind_name[v], wm.m[0], wm.m[1], wm.m[2],
        ndiff, mm.px.size(), maxd);
  }

  if (do_packet) {
    // rays of waves 0..2 of sample 0: primary, first bounce, second bounce
    lc_params P = packed.params;
    q.enqueueWriteBuffer(dev.params, CL_TRUE, 0, sizeof(P), &P);
    kg.setArg(gen_sample_arg, cl_uint(0));
    StageTimes tm;
    launch(kg, tm.gen);
    cl::Buffer st_copy(ctx.context, CL_MEM_READ_WRITE, size_t(kFloatComps) * npix * sizeof(float));
    cl::Buffer su_copy(ctx.context, CL_MEM_READ_WRITE, size_t(kUintComps) * npix * sizeof(cl_uint));
    const size_t pl = 8;
    const cl::NDRange pg(round_up(npix / o.packet, pl)), plocal(pl);
    for (int d = 0; d < 3; ++d) {
      q.enqueueCopyBuffer(st, st_copy, 0, 0, size_t(kFloatComps) * npix * sizeof(float));
      q.enqueueCopyBuffer(su, su_copy, 0, 0, size_t(kUintComps) * npix * sizeof(cl_uint));
      q.finish();
      std::vector<cl_uint> flags(npix);
      q.enqueueReadBuffer(su, CL_TRUE, kFlags * npix * sizeof(cl_uint), npix * sizeof(cl_uint),
                          flags.data());
      size_t alive = std::count_if(flags.begin(), flags.end(), [](cl_uint f) { return f & 1u; });
      double best_s = 1e30, best_p = 1e30;
      std::vector<float> ts(npix), tp(npix);
      std::vector<cl_uint> ps(npix), pp(npix);
      for (int r = 0; r < o.reps + 1; ++r) {
        if (d == 0 && r == 0) {
          std::fflush(stdout);
          std::printf("\n=== first launch of wf_trace_single, wf_trace_packet\n");
          std::fflush(stdout);
        }
        Tick t;
        q.enqueueNDRangeKernel(kts, cl::NullRange, wg, wl);
        q.finish();
        if (r) best_s = std::min(best_s, since(t));
        q.enqueueReadBuffer(st, CL_TRUE, kHT * npix * sizeof(float), npix * sizeof(float),
                            ts.data());
        q.enqueueReadBuffer(su, CL_TRUE, kPrim * npix * sizeof(cl_uint), npix * sizeof(cl_uint),
                            ps.data());
        t = Tick();
        q.enqueueNDRangeKernel(ktp, cl::NullRange, pg, plocal);
        q.finish();
        if (r) best_p = std::min(best_p, since(t));
        q.enqueueReadBuffer(st, CL_TRUE, kHT * npix * sizeof(float), npix * sizeof(float),
                            tp.data());
        q.enqueueReadBuffer(su, CL_TRUE, kPrim * npix * sizeof(cl_uint), npix * sizeof(cl_uint),
                            pp.data());
      }
      size_t same = 0;
      for (uint32_t i = 0; i < npix; ++i)
        if (flags[i] & 1u) same += ps[i] == pp[i] || ts[i] == tp[i];
      std::printf(
          "packet traversal, wave %d (%zu alive rays): single %.2f Mrays/s, packet of %d %.2f "
          "Mrays/s (x%.2f); same hit %.4f%%\n",
          d, alive, alive / best_s * 1e-6, o.packet, alive / best_p * 1e-6, best_s / best_p,
          100.0 * same / std::max<size_t>(alive, 1));
      // advance the copy by one bounce
      q.enqueueCopyBuffer(st_copy, st, 0, 0, size_t(kFloatComps) * npix * sizeof(float));
      q.enqueueCopyBuffer(su_copy, su, 0, 0, size_t(kUintComps) * npix * sizeof(cl_uint));
      q.finish();
      launch(kt, tm.trace);
      ks.setArg(gen_sample_arg, cl_uint(d));
      ks.setArg(gen_sample_arg + 1, cl_uint(0));
      launch(ks, tm.shade);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "lucent_proto: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--width")
      o.width = std::stoi(next());
    else if (a == "--height")
      o.height = std::stoi(next());
    else if (a == "--spp")
      o.spp = std::stoi(next());
    else if (a == "--reps")
      o.reps = std::stoi(next());
    else if (a == "--local")
      o.local = std::stoi(next());
    else if (a == "--wave-local")
      o.wave_local = std::stoi(next());
    else if (a == "--packet")
      o.packet = std::stoi(next());
    else if (a == "--pk")
      o.pk = std::stoi(next());
    else if (a == "--packet-rays")
      o.packet_rays = true;
    else if (a == "--modes")
      o.modes = next();
    else if (a == "--extra")
      o.extra = next();
    else if (a == "--fast-math")
      o.fast_math = true;
    else if (a == "--wall")
      g_wall = true;
    else if (a[0] != '-' && o.scene.empty())
      o.scene = a;
    else {
      std::fprintf(stderr, "lucent_proto: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  if (o.scene.empty()) {
    std::fprintf(stderr, "usage: lucent_proto SCENE [--width W --height H --spp N --reps N ...]\n");
    return 2;
  }
  try {
    return run(o);
  } catch (const lucent::Error& e) {
    std::fprintf(stderr, "lucent_proto: error: %s\n", e.what());
    return 1;
  } catch (const cl::Error& e) {
    std::fprintf(stderr, "lucent_proto: OpenCL error: %s (%d)\n", e.what(), e.err());
    return 1;
  }
}
