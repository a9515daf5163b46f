// `lucent converge SCENE`: error against a reference for a ladder of sample counts or time budgets
// and several speed/accuracy settings; prints the table and the fitted slopes, writes a CSV and an
// SVG plot (lucent/converge.hpp).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/stop_signals.hpp"
#include "core/file_io.hpp"
#include "image/image_probe.hpp"
#include "lucent/compare.hpp"
#include "lucent/converge.hpp"
#include "lucent/error.hpp"
#include "lucent/image.hpp"
#include "lucent/limits.hpp"
#include "lucent/reference.hpp"
#include "lucent/session.hpp"
#include "lucent/types.hpp"

namespace lucent::cli {

namespace {

struct ConvergeArgs {
  std::string scene;
  std::string csv, reference, save_reference, device;
  std::vector<std::string> plots;
  int reference_spp = 0;
  bool reference_cpu = false;
  std::vector<std::string> settings;
  std::vector<int> spp_ladder;
  std::vector<double> time_ladder;
  int max_spp = 64;
  int width = 0, height = 0;
  bool quiet = false;
};

ConvergeArgs& converge_args() {
  static ConvergeArgs a;
  return a;
}

std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_stop_signal = 0;
/// SIGINT, SIGTERM (Slurm's at a job's time limit; it killed the study, without the CSV or plots
/// of the rungs done) and SIGHUP end the study after the current rung; a second one from a second
/// after the first stops at once (stop_signals.hpp).
extern "C" void on_converge_signal(int sig) {
  if (!first_stop_signal(sig)) return;
  g_stop_signal = sig;
  g_stop.store(true);
}

/// A file the command reads, by what it is for messages: "the scene file", "the --reference
/// image", "an input of the scene (<path>)".
struct Input {
  std::string path, what;
};

/// Fails before any rendering when `path` cannot be written or is one of `inputs` (whose content
/// it would replace). (It opened the file to test it: a FIFO waited for a reader for ever, and a
/// device was refused only by the write after the whole study.)
void check_writable(const std::string& path, const std::vector<Input>& inputs) {
  for (const Input& in : inputs)
    if (io::same_file(path, in.path))
      throw Error(path + ": is " + in.what + "; refusing to overwrite it");
  io::check_output_file(path, {});
}

/// The outputs, each with its option: --csv, every --plot, --save-reference.
std::vector<Input> converge_outputs(const ConvergeArgs& a) {
  std::vector<Input> out;
  if (!a.csv.empty()) out.push_back({a.csv, "--csv"});
  for (const std::string& plot : a.plots) out.push_back({plot, "--plot"});
  if (!a.save_reference.empty()) out.push_back({a.save_reference, "--save-reference"});
  return out;
}

/// Checks every output against the inputs and against the outputs before it (two outputs on one
/// file would leave only the last one written).
void check_outputs(const ConvergeArgs& a, const std::vector<Input>& inputs) {
  const std::vector<Input> outputs = converge_outputs(a);
  for (size_t i = 0; i < outputs.size(); ++i) {
    for (size_t j = 0; j < i; ++j)
      if (io::same_file(outputs[i].path, outputs[j].path))
        throw Error(outputs[i].path + ": given as " + outputs[j].what + " and as " +
                    outputs[i].what + "; give each output its own file");
    check_writable(outputs[i].path, inputs);
  }
}

void write_text(const std::string& path, const std::string& text) {
  io::write_file_atomic(path, text);  // checked to the last byte, never left half-written
}

// The --reference image, read once: a linear image, and not a lucent render at the ladder's own
// seed.
RenderResult read_reference(const std::string& path, std::uint32_t ladder_seed) {
  image_detail::Format format;
  RenderResult r = image_detail::read_render(path, &format);
  // a NaN or an infinity makes every error against the reference NaN (and the verdict nonsense)
  check_comparable_image(r, path);
  // an 8-bit (or 16-bit PNG) image holds display values, tone-mapped and clipped: every relMSE
  // against it would measure the display transform, not the render's error
  if (image_detail::is_display_format(format))
    throw Error(path + ": a " + image_detail::format_name(format) +
                " image holds display values (tone-mapped, clipped), not radiance: give a .exr, "
                ".pfm or .hdr reference (lucent render SCENE --seed S -o ref.exr, S not the "
                "scene's seed)");
  // a lucent render at the ladder's seed holds the rungs' own samples (the same numbers for the
  // same pixel, index and dimension): its error against them is hidden
  if (!r.sampler.empty() && r.seed == ladder_seed)
    throw Error(path + ": rendered with seed " + std::to_string(r.seed) +
                ", the ladder's: its samples include the rungs' own, which would hide their "
                "error; render it with another --seed, or let converge render it "
                "(--reference-spp, --save-reference)");
  return r;
}

}  // namespace

CLI::App* add_converge_command(CLI::App& app) {
  ConvergeArgs& a = converge_args();
  CLI::App* cmd = app.add_subcommand(
      "converge", "Error against a reference for a ladder of spp or time budgets and settings");
  cmd->add_option("scene", a.scene, "Scene file (JSON)")->required()->check(non_empty());
  cmd->add_option("--csv", a.csv,
                  "Write setting,spp,seconds,samples_per_s,rmse,relmse,noise_relmse,rays_per_s,"
                  "reference_noise_relmse,estimated_relmse,halves_relmse")
      ->check(non_empty());
  cmd->add_option("--plot", a.plots,
                  "Write a plot of relMSE against time (log-log): .svg, or .png (raster); may be "
                  "given more than once")
      ->check(non_empty());
  auto* ref = cmd->add_option("--reference", a.reference,
                              "Reference image (.exr with var.*/n layers, .pfm, ...)")
                  ->check(non_empty());
  auto* ref_spp = cmd->add_option("--reference-spp", a.reference_spp,
                                  "Render the reference with this many spp (default: 16 x the "
                                  "largest rung, at least 256, at most 2^24; 1024 with "
                                  "--time-ladder)")
                      ->check(CLI::Range(1, limits::kMaxSpp));
  auto* ref_cpu = cmd->add_flag("--reference-cpu", a.reference_cpu,
                                "Render the reference with the scalar reference integrator");
  ref->excludes(ref_spp)->excludes(ref_cpu);
  auto* save_ref =
      cmd->add_option("--save-reference", a.save_reference,
                      "Write the rendered reference to this .exr (reuse it with --reference)")
          ->check(non_empty());
  // a reference given is not rendered: there would be nothing to save (it was silently ignored)
  ref->excludes(save_ref);
  cmd->add_option("--settings", a.settings,
                  "Comma-separated settings, knobs joined by +: default, fast-math, "
                  "double, float, no-specialize, no-mis, mis, max_depth=N, rr_depth=N, filter=" +
                      type_names<FilterType>("|") +
                      "[:R], integrator=" + type_names<IntegratorType>("|") +
                      ", sampler=" + type_names<SamplerType>("|") +
                      ", clamp=X, caustics, no-caustics, splits=N, adaptive, min-spp=N, "
                      "target-error=E (default: default)")
      ->delimiter(',')
      ->check(non_empty());
  auto* spp = cmd->add_option("--spp-ladder", a.spp_ladder, "Samples per pixel of each rung")
                  ->delimiter(',')
                  ->check(CLI::Range(1, limits::kMaxSpp));
  auto* time = cmd->add_option("--time-ladder", a.time_ladder, "Seconds of rendering per rung")
                   ->delimiter(',')
                   ->check(lucent::cli::seconds_limit());
  spp->excludes(time);
  cmd->add_option("--max-spp", a.max_spp,
                  "Default ladder: powers of two from 1 to this (default 64)")
      ->check(CLI::Range(1, limits::kMaxSpp / 16))  // the reference renders 16x the top rung
      // a ladder given makes it meaningless (it was ignored without a word, and the reference's
      // default spp followed the ladder given)
      ->excludes(spp)
      ->excludes(time);
  cmd->add_option("--width", a.width, "Image width (overrides the scene)")
      ->check(CLI::Range(1, limits::kMaxImageSize));
  cmd->add_option("--height", a.height, "Image height (overrides the scene)")
      ->check(CLI::Range(1, limits::kMaxImageSize));
  cmd->add_option("--device", a.device,
                  "OpenCL device: index or name substring, a comma-separated list of them or "
                  "'all' to share the renders (env LUCENT_DEVICE)")
      ->check(non_empty());
  cmd->add_flag("-q,--quiet", a.quiet,
                "Print only the slopes (and, with several settings, the time each takes to the "
                "common error)");
  return cmd;
}

/// What a setting buys: the time each setting takes to reach the largest of the settings' last
/// errors (an error every setting reaches), against the first setting's.
void print_time_to_common_error(const ConvergeResult& result) {
  if (result.fits.size() < 2) return;
  double common = 0;
  std::map<std::string, std::vector<ConvergePoint>> by_setting;
  for (const ConvergePoint& p : result.points) by_setting[p.setting].push_back(p);
  for (const ConvergeFit& f : result.fits) {
    const auto& pts = by_setting[f.setting];
    if (!pts.empty()) common = std::max(common, pts.back().relmse);
  }
  if (!(common > 0)) return;
  std::printf("\ntime to relMSE %.3g (reached by every setting; interpolated on log-log axes):\n",
              common);
  double first = 0;
  bool first_bound = false;
  for (size_t k = 0; k < result.fits.size(); ++k) {
    const ConvergeFit& f = result.fits[k];
    const std::vector<ConvergePoint>& pts = by_setting[f.setting];
    const double t = time_to_relmse(pts, common);
    // a setting already below the error at its first rung (a target-error setting is one render,
    // often far below it) reached it sooner than that rung's time, which only bounds it: it was
    // printed as the time to the error ("x10.88 of default" for a render 20 times below it)
    const bool bound = !pts.empty() && pts.front().relmse < common;
    if (k == 0) first = t, first_bound = bound;
    // the ratio to the first setting's time: a bound when one of the two times is (the first
    // setting's bound made every other ratio a lower bound, printed as a value: "x0.22 of
    // target-error=1e-3" for a setting at least 0.22 times as slow), none when both are
    std::string ratio;
    if (k == 0) {
      ratio = "x1.00";
    } else if (bound && first_bound) {
      ratio = "x?";
    } else {
      char buf[48];
      std::snprintf(buf, sizeof buf, "x%s%.2f",
                    bound         ? "<="
                    : first_bound ? ">="
                                  : "",
                    first > 0 ? t / first : 0.0);
      ratio = buf;
    }
    char time[48];
    std::snprintf(time, sizeof time, "%s%.3f", bound ? "<= " : "", t);
    std::printf("  %-22s %12s s  (%s of %s%s)\n", f.setting.c_str(), time, ratio.c_str(),
                result.fits.front().setting.c_str(),
                bound ? "; already below it at its first rung" : "");
  }
}

int run_converge_command() {
  ConvergeArgs& a = converge_args();
  // the table goes to standard output before the CSV and the plots are written: a pipe closed
  // early (`| head`) killed the study there, its files never written, with no line; the write
  // fails instead, and the status is 1 with "standard output: cannot write (Broken pipe)"
  std::signal(SIGPIPE, SIG_IGN);
  for (const std::string& plot : a.plots) {
    std::string ext = io::lower_extension(plot);
    if (ext != ".svg" && ext != ".png")
      throw Error(plot + ": unknown plot format '" + ext + "' (use .svg or .png)");
  }
  if (!a.save_reference.empty()) {
    // written with its variance layers and seed (write_render_exr): OpenEXR only
    if (io::lower_extension(a.save_reference) != ".exr")
      throw Error(a.save_reference + ": --save-reference writes OpenEXR: use an .exr file");
  }
  std::vector<Input> inputs{{a.scene, "the scene file"}};
  if (!a.reference.empty()) inputs.push_back({a.reference, "the --reference image"});
  check_outputs(a, inputs);

  ConvergeOptions opt;
  try {
    opt.settings = parse_converge_settings(a.settings);
  } catch (const Error& e) {
    throw Error(std::string("--settings: ") + e.what());
  }
  if (opt.settings.empty()) opt.settings.push_back(ConvergeSetting{});
  opt.time_ladder = a.time_ladder;
  opt.spp_ladder = a.time_ladder.empty()
                       ? (a.spp_ladder.empty() ? default_spp_ladder(a.max_spp) : a.spp_ladder)
                       : std::vector<int>{};
  opt.render.cancel = &g_stop;
  // before the scene is loaded and the reference rendered: a setting that would render nothing
  check_convergence_options(opt);

  Scene scene = load_scene(a.scene);
  {
    // the files the scene reads (images, meshes) are inputs too
    const std::vector<std::string> files = scene_inputs(a.scene, scene);
    for (size_t i = 1; i < files.size(); ++i)
      inputs.push_back({files[i], "an input of the scene (" + files[i] + ")"});
    check_outputs(a, inputs);
  }
  if (a.width > 0) scene.film.width = a.width;
  if (a.height > 0) scene.film.height = a.height;
  check_convergence_options(opt, &scene);  // the settings against the scene's integrator

  // until the outputs are written (they were given back after the last rung: a signal while the
  // CSV and the plots were written killed the process, with none of them and a temporary file)
  // (given back before the return: a stop between the last check and the end was swallowed)
  std::optional<StopSignalScope> stop_signals;
  stop_signals.emplace(on_converge_signal);
  // stopped before a rung was done: no results to write, 128 + the signal (it said "error:
  // interrupted while rendering the reference", exit 1); a reference rendered and saved is said
  bool reference_saved = false;
  auto stopped_early = [&](const char* during) {
    const int sig = g_stop_signal ? static_cast<int>(g_stop_signal) : SIGINT;
    std::fprintf(stderr, "lucent: interrupted by %s %s: %s\n", signal_name(sig), during,
                 reference_saved ? ("no results written (the reference is in " +
                                    one_line(a.save_reference) + ")")
                                       .c_str()
                                 : "nothing written");
    return 128 + sig;
  };
  // one session renders the kernel reference and every rung (a different seed is only data)
  Renderer renderer(session_options(a.device));
  renderer.set_cancel_flag(&g_stop);
  opt.renderer = &renderer;
  RenderResult reference;
  if (!a.reference.empty()) {
    reference = read_reference(a.reference, scene.integrator.seed);
    if (reference.mean.width != scene.film.width || reference.mean.height != scene.film.height)
      throw Error(a.reference + ": size " + std::to_string(reference.mean.width) + "x" +
                  std::to_string(reference.mean.height) + " differs from the scene's film (" +
                  std::to_string(scene.film.width) + "x" + std::to_string(scene.film.height) + ")");
  } else {
    // (opt.spp_ladder is empty with a time ladder)
    const int spp = a.reference_spp > 0 ? a.reference_spp : default_reference_spp(opt.spp_ladder);
    Scene rs = scene;
    rs.integrator.seed = reference_seed(scene.integrator.seed);  // independent of the ladder
    // independent samples: the reference's own noise is what its variances say
    rs.integrator.sampler = SamplerType::Independent;
    if (!a.quiet)
      std::fprintf(stderr, "reference: %d spp with the %s (seed %u)...\n", spp,
                   a.reference_cpu ? "reference integrator" : "kernel",
                   static_cast<unsigned>(rs.integrator.seed));
    try {
      if (a.reference_cpu) {
        ReferenceOptions ro;
        ro.spp = spp;
        ro.cancel = &g_stop;
        reference = render_reference(rs, ro);
      } else {
        renderer.set_scene(rs);
        reclaim_stop_handler(on_converge_signal);  // from PoCL's LLVM (stop_signals.hpp)
        renderer.render(static_cast<std::uint64_t>(spp));
        reference = renderer.result();
      }
    } catch (const Error&) {
      // a stop signal during the kernel build, where the build failed on it (PoCL's LLVM, when
      // its handlers were in place) or it cancelled a wait for another process's build: the
      // interruption
      if (!g_stop.load()) throw;
    }
    if (reference.cancelled || g_stop.load()) return stopped_early("while rendering the reference");
    if (!a.quiet)
      std::fprintf(stderr, "reference: %llu spp in %.1f s\n",
                   static_cast<unsigned long long>(reference.spp), reference.seconds);
    if (!a.save_reference.empty()) {
      write_render_exr(a.save_reference, reference);
      reference_saved = true;
    }
  }

  // each setting's kernel build may give PoCL's LLVM the handlers: taken back after each pass
  // of a rung (the first setting's first rung came before any reclaim) and at each rung
  opt.render.on_progress = [](const RenderProgress&) { reclaim_stop_handler(on_converge_signal); };
  opt.on_point = [](const ConvergePoint&) { reclaim_stop_handler(on_converge_signal); };
  if (!a.quiet) {
    std::printf("%-22s %7s %9s %10s %11s %11s %11s\n", "setting", "spp", "seconds", "Msamples/s",
                "RMSE", "relMSE", "noise");
    std::fflush(stdout);
    opt.on_point = [](const ConvergePoint& p) {
      reclaim_stop_handler(on_converge_signal);
      std::printf("%-22s %7llu %9.3f %10.3f %11.4e %11.4e %11.4e\n", p.setting.c_str(),
                  static_cast<unsigned long long>(p.spp), p.seconds, p.samples_per_second * 1e-6,
                  p.rmse, p.relmse, p.noise_relmse);
      std::fflush(stdout);
    };
  }
  ConvergeResult result = run_convergence(scene, reference, opt);
  if (result.points.empty() && g_stop.load()) return stopped_early("before a rung was done");

  std::printf("%sslope of log(relMSE) against log(time) (about -1 when unbiased; RMSE: half):\n",
              a.quiet ? "" : "\n");
  // "n/a": a slope needs rungs of two different spp (it printed 0.00 for one rung)
  auto slope = [](double v, int width) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%*.2f", width, v);
    return std::isnan(v) ? std::string(static_cast<size_t>(width) - 3, ' ') + "n/a"
                         : std::string(buf);
  };
  for (const ConvergeFit& f : result.fits)
    // (the tail's rungs as many as there are, up to 3: two said "last 3 rungs")
    std::printf("  %-22s %s  (against spp %s, last %zu rung%s %s)  %s\n", f.setting.c_str(),
                slope(f.slope_time, 6).c_str(), slope(f.slope_spp, 5).c_str(),
                std::min<std::size_t>(3, f.points), f.points == 1 ? "" : "s",
                slope(f.tail_slope_spp, 5).c_str(), f.verdict.c_str());

  print_time_to_common_error(result);

  if (!a.csv.empty()) write_text(a.csv, convergence_csv(result));
  const std::string title = std::filesystem::path(a.scene).filename().string() + ", " +
                            std::to_string(scene.film.width) + "x" +
                            std::to_string(scene.film.height) + ": relMSE against render time";
  for (const std::string& plot : a.plots) {
    if (io::lower_extension(plot) == ".png")
      write_image(plot, convergence_image(result, title));
    else
      write_text(plot, convergence_svg(result, title));
  }
  stop_signals.reset();  // a signal from here has its default action
  if (g_stop.load()) {
    const int sig = g_stop_signal ? static_cast<int>(g_stop_signal) : SIGINT;
    std::fprintf(stderr, "lucent: interrupted: the results cover the rungs rendered so far\n");
    return 128 + sig;
  }
  return 0;
}

}  // namespace lucent::cli
