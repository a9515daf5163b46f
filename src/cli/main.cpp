// lucent: the command-line front end. A thin layer over the library; every failure ends with one
// line on stderr ("lucent: error: ...") and a non-zero exit status.
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "lucent/compare.hpp"
#include "lucent/limits.hpp"
#include "lucent/lucent.hpp"
#include "lucent/reference.hpp"
#include "lucent/types.hpp"

namespace {

std::atomic<bool> g_interrupted{false};

extern "C" void on_sigint(int) {
  g_interrupted.store(true);     // the render stops after the current pass and writes the image
  std::signal(SIGINT, SIG_DFL);  // a second Ctrl-C stops at once
}

std::string format_duration(double s) {
  char buf[32];
  if (s < 60) {
    std::snprintf(buf, sizeof buf, "%.1fs", s);
  } else {
    int m = static_cast<int>(s / 60);
    std::snprintf(buf, sizeof buf, "%dm%02ds", m, static_cast<int>(s - 60 * m));
  }
  return buf;
}

/// " [A 55%, B 45%]": each device's share of the samples, when several share a render.
std::string device_shares(const std::vector<lucent::DeviceShare>& devices) {
  if (devices.size() < 2) return "";
  std::uint64_t total = 0;
  for (const auto& d : devices) total += d.samples;
  std::string out = " [";
  for (size_t i = 0; i < devices.size(); ++i) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s%s %.0f%%", i ? ", " : "", devices[i].device.c_str(),
                  total ? 100.0 * double(devices[i].samples) / double(total) : 0.0);
    out += buf;
  }
  return out + "]";
}

std::string format_bytes(std::uint64_t b) {
  char buf[32];
  double g = double(b) / (1024.0 * 1024.0 * 1024.0);
  if (g >= 1)
    std::snprintf(buf, sizeof buf, "%.1f GiB", g);
  else
    std::snprintf(buf, sizeof buf, "%.0f MiB", double(b) / (1024.0 * 1024.0));
  return buf;
}

/// Peak resident memory of this process so far, in MiB (host side: scene, BVH, film, and the
/// driver's own allocations; a GPU's device memory is not included).
double peak_host_mib() {
  struct rusage ru {};
  if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
  return double(ru.ru_maxrss) / 1024.0;  // Linux reports KiB
}

/// Fails early (before rendering) when the output cannot be written.
void check_output_path(const std::string& out) {
  namespace fs = std::filesystem;
  std::string ext = fs::path(out).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".png" && ext != ".pfm" && ext != ".exr")
    throw lucent::Error(out + ": unknown output format '" + ext + "' (use .png, .pfm or .exr)");
  std::error_code ec;
  if (fs::is_directory(out, ec)) throw lucent::Error(out + ": is a directory");
  bool existed = fs::exists(out, ec);
  errno = 0;
  std::FILE* f = std::fopen(out.c_str(), "ab");
  if (!f)
    throw lucent::Error(out + ": cannot write output (" + std::string(std::strerror(errno)) + ")");
  std::fclose(f);
  if (!existed) fs::remove(out, ec);
}

int cmd_devices() {
  auto devices = lucent::list_devices();
  std::printf("%-3s %-28s %-40s %-5s %4s %10s  %-22s %s\n", "#", "platform", "device", "type",
              "CUs", "memory", "OpenCL C", "fp64");
  for (const auto& d : devices)
    std::printf("%-3d %-28s %-40s %-5s %4u %10s  %-22s %s\n", d.index, d.platform.c_str(),
                d.name.c_str(), d.type.c_str(), d.compute_units,
                format_bytes(d.global_memory).c_str(), d.opencl_c_version.c_str(),
                d.fp64 ? "yes" : "no");
  return 0;
}

struct RenderArgs {
  std::string scene;
  std::string output;
  int spp = 0;
  int width = 0;
  int height = 0;
  std::string device;
  long long seed = -1;
  double time_limit = 0;
  std::string integrator;
  bool quiet = false;
  bool reference = false;         ///< the scalar reference integrator instead of the kernel
  std::vector<std::string> aovs;  ///< extra outputs: albedo, normal, depth, variance
  bool fast_math = false;
  std::string precision = "float";
  bool no_specialize = false;
  lucent::cli::SamplingArgs sampling;  ///< --sampler, --clamp, --target-error, --min-spp
};

/// <output stem>.<name>.exr beside the main output.
std::string aov_path(const std::string& output, const std::string& name) {
  std::filesystem::path p(output);
  return (p.parent_path() / (p.stem().string() + "." + name + ".exr")).string();
}

/// Renders and writes the requested AOV images (linear EXR) after the main render, on the same
/// session: the BVH is reused, only the AOV kernel is built.
void write_aovs(const RenderArgs& a, const lucent::Scene& scene, lucent::Renderer* renderer,
                const lucent::RenderResult& main_result) {
  for (const std::string& name : a.aovs) {
    std::string path = aov_path(a.output, name);
    if (name == "variance") {
      lucent::write_image(path, main_result.variance);
    } else {
      lucent::Scene s = scene;
      s.integrator.type = lucent::cli::parse_integrator(name);
      renderer->set_scene(s);
      renderer->reset();
      renderer->render(std::max<std::uint64_t>(1, main_result.spp));
      lucent::write_image(path, renderer->result().mean);
    }
    if (!a.quiet) std::fprintf(stderr, "%s: %s AOV\n", path.c_str(), name.c_str());
  }
}

int cmd_render(const RenderArgs& a) {
  check_output_path(a.output);
  lucent::Scene scene = lucent::load_scene(a.scene);
  if (a.width > 0) scene.film.width = a.width;
  if (a.height > 0) scene.film.height = a.height;
  if (a.seed >= 0) scene.integrator.seed = static_cast<std::uint32_t>(a.seed);
  if (!a.integrator.empty()) scene.integrator.type = lucent::cli::parse_integrator(a.integrator);
  lucent::cli::apply_sampling_options(a.sampling, scene);

  lucent::RenderOptions opt;
  opt.spp = a.spp;
  opt.time_limit = a.time_limit;
  opt.fast_math = a.fast_math;
  opt.precision = lucent::parse_precision(a.precision);
  opt.specialize = !a.no_specialize;
  opt.cancel = &g_interrupted;
  const bool tty = isatty(STDERR_FILENO);
  double last_print = -10;
  bool printed = false;
  if (!a.quiet) {
    opt.on_progress = [&](const lucent::RenderProgress& p) {
      if (p.elapsed < 1.0) return;  // short renders stay silent
      if (!tty && p.elapsed - last_print < 2.0) return;
      last_print = p.elapsed;
      double frac = p.samples_target > 0 ? double(p.samples_done) / double(p.samples_target)
                                         : (p.time_limit > 0 ? p.elapsed / p.time_limit : 0);
      frac = std::min(1.0, frac);
      double eta = frac > 0 ? p.elapsed * (1 - frac) / frac : 0;
      std::fprintf(stderr, "%s%5.1f%%  %llu spp  %.2f Msamples/s  elapsed %s  ETA %s%s%s",
                   tty ? "\r" : "", 100 * frac, static_cast<unsigned long long>(p.samples_done),
                   p.samples_per_second * 1e-6, format_duration(p.elapsed).c_str(),
                   format_duration(eta).c_str(), device_shares(p.devices).c_str(),
                   tty ? "   " : "\n");
      std::fflush(stderr);
      printed = true;
    };
  }
  auto previous = std::signal(SIGINT, on_sigint);
  lucent::RenderResult r;
  std::optional<lucent::Renderer> renderer;
  double wall = 0;  // of the kernel render (several devices: their passes overlap)
  if (a.reference) {
    if (a.time_limit > 0) throw lucent::Error("--time is not supported with --reference");
    if (a.sampling.target_error > 0)
      throw lucent::Error("--target-error is not supported with --reference");
    lucent::ReferenceOptions ro;
    ro.spp = a.spp;
    ro.cancel = &g_interrupted;
    r = lucent::render_reference(scene, ro);
  } else {
    lucent::SessionOptions so = lucent::cli::session_options(a.device);
    so.precision = opt.precision;
    so.fast_math = opt.fast_math;
    so.specialize = opt.specialize;
    renderer.emplace(so);
    renderer->set_cancel_flag(&g_interrupted);
    renderer->set_scene(scene);
    std::uint64_t spp = a.spp > 0 ? static_cast<std::uint64_t>(a.spp)
                                  : (a.time_limit > 0 ? 0 : scene.integrator.spp);
    auto t0 = std::chrono::steady_clock::now();
    if (a.sampling.target_error > 0)
      renderer->render_adaptive(lucent::cli::adaptive_options(a.sampling, a.spp, a.time_limit),
                                opt.on_progress);
    else
      renderer->render(spp, a.time_limit, opt.on_progress);
    wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r = renderer->result();
  }
  std::signal(SIGINT, previous);
  if (printed && tty) std::fprintf(stderr, "\n");

  lucent::DisplaySettings display{scene.film.transfer, scene.film.gamma, scene.film.exposure,
                                  scene.film.tonemap};
  std::string ext = std::filesystem::path(a.output).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".exr")
    lucent::write_render_exr(a.output, r);  // with var.R/G/B and n layers (docs/compare.md)
  else
    lucent::write_image(a.output, r.mean, display);
  if (r.nonfinite > 0)
    std::fprintf(stderr, "lucent: warning: %llu non-finite sample(s) (NaN or Inf) were dropped\n",
                 static_cast<unsigned long long>(r.nonfinite));
  // one device: its pass time; several: the wall time of the render, when they overlapped
  double seconds = r.devices.size() > 1 ? wall : r.seconds;
  if (!a.quiet)
    std::fprintf(
        stderr,
        "%s: %dx%d, %llu spp in %.2f s (%.2f Msamples/s, %.2f Mrays/s, build %.2f s, peak host "
        "memory %.0f MiB) on %s%s\n",
        a.output.c_str(), scene.film.width, scene.film.height,
        static_cast<unsigned long long>(r.spp), seconds,
        seconds > 0 ? double(r.spp) * scene.film.width * scene.film.height / seconds * 1e-6 : 0,
        seconds > 0 ? double(r.rays) / seconds * 1e-6 : 0, r.build_seconds, peak_host_mib(),
        r.device.c_str(), device_shares(r.devices).c_str());
  if (!a.quiet && r.target_error > 0)
    std::fprintf(stderr, "%s: adaptive: %llu spp on average, estimated relMSE %.3g (target %.3g)\n",
                 a.output.c_str(), static_cast<unsigned long long>(r.spp), r.estimated_relmse,
                 r.target_error);
  if (!r.cancelled && !a.reference) write_aovs(a, scene, &*renderer, r);
  if (r.cancelled) {
    std::fprintf(stderr, "lucent: interrupted: wrote %s with the %llu spp accumulated so far\n",
                 a.output.c_str(), static_cast<unsigned long long>(r.spp));
    return 130;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"lucent: a physically based OpenCL path tracer", "lucent"};
  app.set_version_flag("--version", std::string("lucent ") + lucent::kVersion);
  app.require_subcommand(1);

  RenderArgs ra;
  CLI::App* render = app.add_subcommand("render", "Render a JSON scene to an image");
  render->add_option("scene", ra.scene, "Scene file (JSON)")->required();
  render
      ->add_option("-o,--output", ra.output,
                   "Output image: .png (8-bit sRGB), .pfm or .exr (linear)")
      ->required();
  render
      ->add_option("--spp", ra.spp,
                   "Samples per pixel (default: the scene's integrator.spp; with --target-error "
                   "the most per pixel, default 16384)")
      ->check(CLI::Range(1, lucent::limits::kMaxSpp));
  render->add_option("--time", ra.time_limit, "Stop after this many seconds of rendering")
      ->check(CLI::PositiveNumber);
  render->add_option("--width", ra.width, "Image width (overrides the scene)")
      ->check(CLI::Range(1, lucent::limits::kMaxImageSize));
  render->add_option("--height", ra.height, "Image height (overrides the scene)")
      ->check(CLI::Range(1, lucent::limits::kMaxImageSize));
  render->add_option("--device", ra.device,
                     "OpenCL device: index or name substring, a comma-separated list of them or "
                     "'all' to share the render (env LUCENT_DEVICE)");
  render->add_option("--seed", ra.seed, "Random seed (overrides the scene)")
      ->check(CLI::Range(0LL, static_cast<long long>(lucent::limits::kMaxSeed)));
  render->add_option("--integrator", ra.integrator,
                     "Override the integrator: " + lucent::type_names<lucent::IntegratorType>());
  render->add_flag("-q,--quiet", ra.quiet, "No progress line or summary");
  render->add_flag(
      "--fast-math", ra.fast_math,
      "Build the kernel with -cl-fast-relaxed-math (faster, not IEEE; see BENCHMARKS.md)");
  render
      ->add_option("--precision", ra.precision,
                   "Ray and geometry arithmetic: float (default) or double (devices with fp64; "
                   "slower, precise at extreme scales; see BENCHMARKS.md)")
      ->check(CLI::IsMember({"float", "double"}));
  render->add_flag("--no-specialize", ra.no_specialize,
                   "Compile the full kernel instead of only the features the scene uses");
  render->add_option("--aov", ra.aovs,
                     "Also write AOV images <stem>.<name>.exr: " +
                         lucent::cli::joined(lucent::cli::aov_names()))
      ->delimiter(',')
      ->check(CLI::IsMember(lucent::cli::aov_names()));
  render->add_flag("--reference", ra.reference,
                   "Render with the scalar CPU reference integrator instead of the kernel");
  lucent::cli::add_sampling_options(render, ra.sampling, true);

  CLI::App* devices = app.add_subcommand("devices", "List OpenCL devices");

  lucent::cli::register_extra_commands(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string msg = e.what();
    // CLI11 reports a missing argument before an unexpected one: name the unknown option first
    for (const std::string& extra : app.remaining(true))
      if (extra.size() > 1 && extra[0] == '-') {
        msg = "unknown option " + extra;
        break;
      }
    for (auto& c : msg)
      if (c == '\n') c = ' ';
    std::fprintf(stderr, "lucent: error: %s (see lucent --help)\n", msg.c_str());
    return 2;
  }

  try {
    if (*render) return cmd_render(ra);
    if (*devices) return cmd_devices();
    return lucent::cli::run_extra_commands(app);
  } catch (const lucent::Error& e) {
    std::fprintf(stderr, "lucent: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "lucent: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lucent: error: %s\n", e.what());
    return 1;
  }
}
