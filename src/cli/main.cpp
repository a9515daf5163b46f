// lucent: the command-line front end. A thin layer over the library; every failure ends with one
// line on stderr ("lucent: error: ...") and a non-zero exit status.
#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "core/file_io.hpp"
#include "lucent/compare.hpp"
#include "lucent/lucent.hpp"
#include "lucent/reference.hpp"

namespace {

std::atomic<bool> g_interrupted{false};
volatile std::sig_atomic_t g_signal = 0;

// Ctrl-C (SIGINT), SIGTERM and SIGHUP: the render stops after the current pass, writes what it
// has and exits with 128 + the signal. A second signal stops at once.
extern "C" void on_stop_signal(int sig) {
  g_signal = sig;
  g_interrupted.store(true);
  std::signal(sig, SIG_DFL);
}

const int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

const char* signal_name(int sig) {
  return sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "SIGINT (Ctrl-C)";
}

// Control characters and bytes that are not UTF-8 in an error message (they come from file names
// and file contents) would break the one-line contract or the terminal: shown escaped.
std::string one_line(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size();) {
    unsigned char c = static_cast<unsigned char>(s[i]);
    int n = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
    bool ok = n > 0 && i + n <= s.size() && !(n == 2 && c < 0xC2);
    for (int k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(s[i + k]) >> 6) == 2;
    if (ok && n == 1 && (c < 0x20 || c == 0x7F)) {
      char buf[8];
      const char* named = c == '\n' ? "\\n" : c == '\r' ? "\\r" : c == '\t' ? "\\t" : nullptr;
      if (!named) std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += named ? named : buf;
      ++i;
    } else if (ok) {
      out.append(s, i, static_cast<size_t>(n));
      i += static_cast<size_t>(n);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
      ++i;
    }
  }
  return out;
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

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// Fails early (before rendering) when `out` cannot be written: not an image format lucent
/// writes, a directory, a directory that does not exist or cannot be written to (tested by
/// creating a file there, as the final write does), a read-only file, or one of the inputs.
void check_output_path(const std::string& out, const std::vector<std::string>& inputs,
                       const char* formats = ".png, .pfm or .exr") {
  namespace fs = std::filesystem;
  if (out.empty()) throw lucent::Error("-o: the output path is empty");
  std::string ext = lower_extension(out);
  if (ext != ".png" && ext != ".pfm" && ext != ".exr")
    throw lucent::Error(out + ": unknown output format '" + ext + "' (use " + formats + ")");
  std::error_code ec;
  if (fs::is_directory(out, ec)) throw lucent::Error(out + ": is a directory");
  for (const std::string& in : inputs)
    if (lucent::io::same_file(out, in))
      throw lucent::Error(out + ": is an input of this render (" + in +
                          "); refusing to overwrite it");
  if (fs::exists(out, ec) && ::access(out.c_str(), W_OK) != 0)
    throw lucent::Error(out + ": cannot write output (" + std::strerror(errno) + ")");
  fs::path dir = fs::path(out).parent_path();
  std::string probe = (dir.empty() ? fs::path(".") : dir).string() + "/.lucent-write-test-" +
                      std::to_string(::getpid());
  int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    int err = errno;
    // a file (not a directory) somewhere on the path reads better as the output's own problem
    throw lucent::Error(out + ": cannot write output (" + std::strerror(err) + ")");
  }
  ::close(fd);
  ::unlink(probe.c_str());
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
};

/// <output stem>.<name>.exr beside the main output.
std::string aov_path(const std::string& output, const std::string& name) {
  std::filesystem::path p(output);
  return (p.parent_path() / (p.stem().string() + "." + name + ".exr")).string();
}

/// Renders and writes the requested AOV images (linear EXR) after the main render; stops when
/// interrupted (the AOVs written so far stay).
void write_aovs(const RenderArgs& a, const lucent::Scene& scene, const lucent::RenderOptions& opt,
                const lucent::RenderResult& main_result) {
  for (const std::string& name : a.aovs) {
    if (g_interrupted.load()) return;
    std::string path = aov_path(a.output, name);
    if (name == "variance") {
      lucent::write_image(path, main_result.variance);
    } else {
      lucent::Scene s = scene;
      s.integrator.type = lucent::cli::parse_integrator(name);
      lucent::RenderOptions o = opt;
      o.on_progress = nullptr;
      o.spp = static_cast<int>(std::max<std::uint64_t>(1, main_result.spp));
      o.time_limit = 0;
      lucent::RenderResult aov = lucent::render(s, o);
      if (aov.cancelled) return;  // a partial AOV is not worth a file
      lucent::write_image(path, aov.mean);
    }
    if (!a.quiet) std::fprintf(stderr, "%s: %s AOV\n", path.c_str(), name.c_str());
  }
}

/// How far an interrupted render got, for its last line.
std::string progress_note(const lucent::RenderResult& r, std::uint64_t target_spp,
                          double time_limit) {
  char buf[160];
  if (!r.samples.empty() && r.spp > 0) {
    size_t covered = 0;
    for (std::uint32_t n : r.samples) covered += n > 0;
    if (covered < r.samples.size()) {  // the reference renders row by row
      std::snprintf(buf, sizeof buf, "%.1f%% of the pixels at %llu spp (the others are black)",
                    100.0 * double(covered) / double(r.samples.size()),
                    static_cast<unsigned long long>(r.spp));
      return buf;
    }
  }
  if (target_spp > 0)
    std::snprintf(
        buf, sizeof buf, "%llu of %llu spp (%.0f%%)", static_cast<unsigned long long>(r.spp),
        static_cast<unsigned long long>(target_spp), 100.0 * double(r.spp) / double(target_spp));
  else
    std::snprintf(buf, sizeof buf, "%llu spp after %.1f of %g s",
                  static_cast<unsigned long long>(r.spp), r.seconds, time_limit);
  return buf;
}

int cmd_render(const RenderArgs& a) {
  check_output_path(a.output, {a.scene});
  for (const std::string& name : a.aovs)
    check_output_path(aov_path(a.output, name), {a.scene, a.output});
  // from here on a stop signal lets the render end its pass and write what it has
  for (int sig : kStopSignals) std::signal(sig, on_stop_signal);
  std::signal(SIGPIPE, SIG_IGN);  // a closed stderr pipe must not cost the image
  lucent::Scene scene = lucent::load_scene(a.scene);
  {
    // the images the scene reads are inputs too
    std::vector<std::string> inputs{a.scene};
    for (const lucent::Texture& t : scene.textures) inputs.push_back(t.path);
    check_output_path(a.output, inputs);
    for (const std::string& name : a.aovs) check_output_path(aov_path(a.output, name), inputs);
  }
  if (g_interrupted.load()) {
    std::fprintf(stderr, "lucent: interrupted by %s before rendering: nothing written\n",
                 signal_name(g_signal));
    return 128 + g_signal;
  }
  if (a.width > 0) scene.film.width = a.width;
  if (a.height > 0) scene.film.height = a.height;
  if (a.seed >= 0) scene.integrator.seed = static_cast<std::uint32_t>(a.seed);
  if (!a.integrator.empty()) scene.integrator.type = lucent::cli::parse_integrator(a.integrator);

  lucent::RenderOptions opt;
  opt.device = a.device;
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
      std::fprintf(stderr, "%s%5.1f%%  %llu spp  %.2f Msamples/s  elapsed %s  ETA %s%s",
                   tty ? "\r" : "", 100 * frac, static_cast<unsigned long long>(p.samples_done),
                   p.samples_per_second * 1e-6, format_duration(p.elapsed).c_str(),
                   format_duration(eta).c_str(), tty ? "   " : "\n");
      std::fflush(stderr);
      printed = true;
    };
  }
  lucent::RenderResult r;
  if (a.reference) {
    if (a.time_limit > 0) throw lucent::Error("--time is not supported with --reference");
    lucent::ReferenceOptions ro;
    ro.spp = a.spp;
    ro.cancel = &g_interrupted;
    r = lucent::render_reference(scene, ro);
  } else {
    r = lucent::render(scene, opt);
  }
  if (printed && tty) std::fprintf(stderr, "\n");

  lucent::DisplaySettings display{scene.film.transfer, scene.film.gamma, scene.film.exposure,
                                  scene.film.tonemap};
  if (lower_extension(a.output) == ".exr")
    lucent::write_render_exr(a.output, r);  // with var.R/G/B and n layers (docs/compare.md)
  else
    lucent::write_image(a.output, r.mean, display);
  if (r.nonfinite > 0)
    std::fprintf(stderr, "lucent: warning: %llu non-finite sample(s) (NaN or Inf) were dropped\n",
                 static_cast<unsigned long long>(r.nonfinite));
  if (!a.quiet)
    std::fprintf(
        stderr,
        "%s: %dx%d, %llu spp in %.2f s (%.2f Msamples/s, %.2f Mrays/s, build %.2f s, peak host "
        "memory %.0f MiB) on %s\n",
        a.output.c_str(), scene.film.width, scene.film.height,
        static_cast<unsigned long long>(r.spp), r.seconds,
        r.seconds > 0 ? double(r.spp) * scene.film.width * scene.film.height / r.seconds * 1e-6 : 0,
        r.seconds > 0 ? double(r.rays) / r.seconds * 1e-6 : 0, r.build_seconds, peak_host_mib(),
        r.device.c_str());
  if (!r.cancelled && !a.reference) write_aovs(a, scene, opt, r);
  if (r.cancelled || g_interrupted.load()) {
    const int sig = g_signal ? static_cast<int>(g_signal) : SIGINT;
    const std::uint64_t target = a.spp > 0
                                     ? std::uint64_t(a.spp)
                                     : (a.time_limit > 0 ? 0 : std::uint64_t(scene.integrator.spp));
    std::fprintf(stderr, "lucent: interrupted by %s: wrote %s with %s%s\n", signal_name(sig),
                 a.output.c_str(), progress_note(r, target, a.time_limit).c_str(),
                 r.cancelled ? "" : " (the AOVs were not all written)");
    return 128 + sig;
  }
  return 0;
}

/// The first floating-point option given a value that is not a finite number, as
/// "--name value" ("" when none): CLI11's range checks let NaN through (every comparison with it
/// is false), and a NaN --time would never end a render.
std::string non_finite_option(const CLI::App& app) {
  std::vector<const CLI::App*> apps{&app};
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    apps.push_back(sub);
  for (const CLI::App* a : apps)
    for (const CLI::Option* o : a->get_options()) {
      if (o->get_type_name().find("FLOAT") == std::string::npos) continue;
      for (const std::string& all : o->results()) {
        std::string value;
        std::istringstream items(all);
        while (std::getline(items, value, ',')) {
          char* end = nullptr;
          double v = std::strtod(value.c_str(), &end);
          if (end != value.c_str() && *end == '\0' && !std::isfinite(v))
            return o->get_name() + " " + value;
        }
      }
    }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  // a file size limit (ulimit -f) must end in an error naming the file, not in a kill
  std::signal(SIGXFSZ, SIG_IGN);
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
  render->add_option("--spp", ra.spp, "Samples per pixel (default: the scene's integrator.spp)")
      ->check(CLI::Range(1, 1 << 24));
  render->add_option("--time", ra.time_limit, "Stop after this many seconds of rendering")
      ->check(CLI::PositiveNumber)
      ->check(CLI::Range(0.0, 1e7));
  render->add_option("--width", ra.width, "Image width (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  render->add_option("--height", ra.height, "Image height (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  render->add_option("--device", ra.device,
                     "OpenCL device: index or name substring (env LUCENT_DEVICE)");
  render->add_option("--seed", ra.seed, "Random seed (overrides the scene)")
      ->check(CLI::Range(0LL, 0xffffffffLL));
  render->add_option(
      "--integrator", ra.integrator,
      "Override the integrator: path, whitted, direct, albedo, normal, depth, ao, primitive");
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
  render
      ->add_option("--aov", ra.aovs,
                   "Also write AOV images <stem>.<name>.exr: albedo, normal, depth, variance")
      ->delimiter(',')
      ->check(CLI::IsMember({"albedo", "normal", "depth", "variance"}));
  render->add_flag("--reference", ra.reference,
                   "Render with the scalar CPU reference integrator instead of the kernel");

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
    if (std::string bad = non_finite_option(app); !bad.empty()) {  // before CLI11's range text
      std::fprintf(stderr, "lucent: error: %s: must be a finite number (see lucent --help)\n",
                   one_line(bad).c_str());
      return 2;
    }
    std::string msg = e.what();
    // CLI11 reports a missing argument before an unexpected one: name the unknown option first
    for (const std::string& extra : app.remaining(true))
      if (extra.size() > 1 && extra[0] == '-') {
        msg = "unknown option " + extra;
        if (extra.find_first_of("./") != std::string::npos)  // a file name, most likely
          msg += " (a file whose name starts with '-' can be given as ./" + extra + ")";
        break;
      }
    for (auto& c : msg)
      if (c == '\n') c = ' ';
    std::fprintf(stderr, "lucent: error: %s (see lucent --help)\n", one_line(msg).c_str());
    return 2;
  }
  if (std::string bad = non_finite_option(app); !bad.empty()) {
    std::fprintf(stderr, "lucent: error: %s: must be a finite number (see lucent --help)\n",
                 one_line(bad).c_str());
    return 2;
  }

  int status = 1;
  try {
    if (*render)
      status = cmd_render(ra);
    else if (*devices)
      status = cmd_devices();
    else
      status = lucent::cli::run_extra_commands(app);
  } catch (const lucent::Error& e) {
    if (!e.details().empty()) std::fprintf(stderr, "%s\n", e.details().c_str());
    std::fprintf(stderr, "lucent: error: %s\n", one_line(e.what()).c_str());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "lucent: error: out of memory (%s)\n",
                 *render ? ("rendering " + one_line(ra.scene)).c_str() : "no scene loaded");
    return 1;
  } catch (const std::exception& e) {
    // not a lucent::Error (a limit of the standard library): name what was being done
    std::fprintf(stderr, "lucent: error: %s: %s\n", *render ? one_line(ra.scene).c_str() : "lucent",
                 one_line(e.what()).c_str());
    return 1;
  }
  // what went to stdout (a table, a comparison) must have been written too
  errno = 0;
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    std::fprintf(stderr, "lucent: error: standard output: cannot write (%s)\n",
                 errno ? std::strerror(errno) : "write error");
    return status == 0 ? 1 : status;
  }
  return status;
}
