// `lucent render SCENE -o OUT`: renders a JSON scene with the kernel (or the reference) and writes
// the image: outputs checked before rendering, written atomically, stop signals honoured
// (SIGINT, SIGTERM, SIGHUP: what was rendered is written, exit 128 + the signal).
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli/checkpoint.hpp"
#include "cli/commands.hpp"
#include "cli/progress_start.hpp"
#include "cli/stop_signals.hpp"
#include "core/file_io.hpp"
#include "image/image_probe.hpp"
#include "lucent/compare.hpp"
#include "lucent/limits.hpp"
#include "lucent/lucent.hpp"
#include "lucent/parts.hpp"
#include "lucent/reference.hpp"
#include "lucent/types.hpp"
#include "render/resources.hpp"
#include "render/sample_stats.hpp"

namespace lucent::cli {

namespace {

std::atomic<bool> g_interrupted{false};
volatile std::sig_atomic_t g_signal = 0;

// Ctrl-C (SIGINT), SIGTERM and SIGHUP: the render stops after the current pass, writes what it
// has and exits with 128 + the signal. A second signal from a second after the first stops at once
// (stop_signals.hpp).
extern "C" void on_stop_signal(int sig) {
  if (!first_stop_signal(sig)) return;
  g_signal = sig;
  g_interrupted.store(true);
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

/// Peak resident memory of this process so far, in MiB (host side: scene, BVH, film, and the
/// driver's own allocations; a GPU's device memory is not included).
double peak_host_mib() {
  struct rusage ru {};
  if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
  return double(ru.ru_maxrss) / 1024.0;  // Linux reports KiB
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

struct RenderArgs {
  std::string scene;
  std::string output;
  int spp = 0;
  int width = 0;
  int height = 0;
  std::string device;
  long long seed = -1;
  int max_depth = 0, rr_depth = 0;  ///< > 0: override integrator.max_depth / rr_depth
  double time_limit = 0;
  std::string integrator;
  bool quiet = false;
  bool reference = false;         ///< the scalar reference integrator instead of the kernel
  std::vector<std::string> aovs;  ///< extra outputs: albedo, normal, depth, variance
  bool fast_math = false;
  std::string precision;  ///< "" : float
  bool no_specialize = false;
  lucent::cli::SamplingArgs sampling;  ///< --sampler, --clamp, --target-error, --min-spp
  std::string samples;          ///< "A:B": a part file of sample indices [A, B) (lucent/parts.hpp)
  std::string checkpoint;       ///< a part file of the samples so far, resumed from when present
  double checkpoint_every = 0;  ///< seconds between checkpoints; 0: not given (the default)
};

/// <output stem>.<name>.exr beside the main output.
std::string aov_path(const std::string& output, const std::string& name) {
  std::filesystem::path p(output);
  return (p.parent_path() / (p.stem().string() + "." + name + ".exr")).string();
}

/// Renders and writes the requested AOV images (linear EXR) after the main render, on the same
/// session (the BVH is reused, only the AOV kernel is built); returns the names of those not
/// written. The variance AOV is the main render's, so an interrupted render writes it too; the
/// others need renders of their own, which an interrupt skips (the AOVs written so far stay).
std::vector<std::string> write_aovs(const RenderArgs& a, lucent::Renderer* renderer,
                                    const lucent::RenderResult& main_result) {
  std::vector<std::string> missing;
  for (const std::string& name : a.aovs) {
    std::string path = aov_path(a.output, name);
    if (name == "variance") {
      lucent::write_image(path, main_result.variance);
    } else if (main_result.cancelled || g_interrupted.load()) {
      missing.push_back(name);
      continue;
    } else {
      lucent::Scene s = renderer->scene();  // (the main scene, or the last AOV's: its type)
      s.integrator.type = lucent::cli::parse_integrator(name);
      try {
        renderer->set_scene(std::move(s));
        reclaim_stop_handler(on_stop_signal);
      } catch (const lucent::Error&) {
        // a stop signal during the AOV's kernel build: where PoCL's LLVM handles it too (its
        // handlers installed again, which reclaim_stop_handler undoes after each build) the
        // build fails; the AOV is not written, as one stopped in its render (it said "kernel
        // build failed", exit 1, with the image written)
        if (!g_interrupted.load()) throw;
        missing.push_back(name);
        continue;
      }
      renderer->reset();
      renderer->render(std::max<std::uint64_t>(1, main_result.spp));
      lucent::RenderResult aov = renderer->result();
      if (aov.cancelled) {  // a partial AOV is not worth a file
        missing.push_back(name);
        continue;
      }
      // with its var.*/n layers, as `--integrator NAME -o x.exr` writes it: without them
      // `lucent compare` took a noisy AOV (ao) for an exact image
      lucent::write_render_exr(path, aov);
    }
    if (!a.quiet) std::fprintf(stderr, "%s: %s AOV\n", one_line(path).c_str(), name.c_str());
  }
  return missing;
}

/// How far an interrupted render got, for its last line.
std::string progress_note(const lucent::RenderResult& r, std::uint64_t target_spp,
                          double time_limit, bool reference) {
  char buf[200];
  if (reference && !r.samples.empty() && target_spp > 0) {
    // the reference renders pixel by pixel, and stops between two samples: its pixels hold
    // all their samples, some (the one it stopped in) or none
    size_t covered = 0;
    double taken = double(r.nonfinite);
    for (std::uint32_t n : r.samples) {
      covered += n > 0;
      taken += n;
    }
    const double all = double(r.samples.size()) * double(target_spp);
    if (taken < all) {
      std::snprintf(buf, sizeof buf,
                    "%.1f%% of its %llu spp per pixel (%.1f%% of the pixels have samples, the "
                    "others are black)",
                    100.0 * taken / all, static_cast<unsigned long long>(target_spp),
                    100.0 * double(covered) / double(r.samples.size()));
      return buf;
    }
  }
  if (r.target_error > 0) {
    // adaptive: --spp is only a cap and the scene's spp means nothing to it ("740 of 64 spp
    // (1156%)"); say where in its plan it stopped
    if (r.pilot_incomplete)
      std::snprintf(buf, sizeof buf, "%llu spp on average, in its pilot of %llu spp (no plan made)",
                    static_cast<unsigned long long>(r.spp),
                    static_cast<unsigned long long>(r.planned_spp));
    else
      std::snprintf(buf, sizeof buf, "%llu of the %llu spp its plan asked for on average (%.0f%%)",
                    static_cast<unsigned long long>(r.spp),
                    static_cast<unsigned long long>(r.planned_spp),
                    r.planned_spp ? 100.0 * double(r.spp) / double(r.planned_spp) : 100.0);
    return buf;
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

/// The outputs' memory, counted before rendering: a render refused up front rather than lost to
/// its write (the resources review: a part file's write took 2.5 times the session's estimate).
/// Without AOVs the session is gone before the output is written (`after`, checked on its own);
/// with them it lives on, and the writes are declared beside it (`beside`).
struct OutputMemory {
  std::uint64_t beside = 0;
  std::string beside_what;  ///< what `beside` holds, for the error line
  std::vector<lucent::render_detail::MemoryPart> after;
};

OutputMemory output_memory(const RenderArgs& a, int fw, int fh, bool part, bool resumed) {
  const std::uint64_t npix = std::uint64_t(fw) * std::uint64_t(fh);
  const std::string film = std::to_string(fw) + "x" + std::to_string(fh);
  const std::uint64_t result_bytes = npix * lucent::render_detail::kResultPixelBytes;
  const std::uint64_t acc_bytes = npix * lucent::render_detail::kAccumulationPixelBytes;
  const std::uint64_t write_bytes =
      part ? lucent::part_write_bytes(fw, fh)
           : (lucent::io::lower_extension(a.output) == ".exr"
                  ? lucent::image_detail::render_exr_write_bytes(fw, fh, true)
                  : lucent::image_detail::image_write_bytes(a.output, fw, fh));
  OutputMemory m;
  if (!a.checkpoint.empty()) {
    // beside the session: a checkpoint's part (the session's sums, added to a resumed render's
    // checkpoint, itself held throughout) and the write of its file; after it, a resumed render's
    // image is made from that part (--checkpoint is refused with --aov and --samples)
    m.beside = checkpoint_beside_bytes(fw, fh, resumed);
    m.beside_what = "the checkpoint's sums and the write of its file (" + film + ")";
    if (resumed)
      m.after.push_back({"the sums of the checkpoint and this render (" + film + ")", acc_bytes,
                         "the film size"});
  }
  if (!a.aovs.empty()) {
    // the main image's write, then each AOV's result and file
    m.beside = write_bytes;
    m.beside_what = "writing " + one_line(a.output) + " and then each --aov image (" + film + ")";
    for (const std::string& name : a.aovs)
      m.beside =
          std::max(m.beside,
                   name == "variance"
                       ? lucent::image_detail::image_write_bytes(aov_path(a.output, name), fw, fh)
                       : result_bytes + lucent::image_detail::render_exr_write_bytes(fw, fh, true));
    return m;
  }
  if (part) {  // the part's copy of the sums, made before the session goes
    m.beside += acc_bytes;
    if (m.beside_what.empty())
      m.beside_what = "the part's copy of the sums of the " + film + " film";
  }
  const std::string kept = part ? "the part's sums of the " + film + " film"
                                : "the result images of the " + film + " film";
  m.after.push_back({kept, part ? acc_bytes : result_bytes, "the film size"});
  m.after.push_back(
      {"writing " + one_line(a.output) + " (" + film + ")", write_bytes, "the film size"});
  return m;
}

/// Writes the output: a part (--samples, taken from the session, which goes before the write's
/// memory), an .exr with var.R/G/B and n layers (docs/compare.md) and the key of its random
/// numbers (RenderResult::seed, sampler), by which `lucent converge` refuses a reference that
/// would replay its ladder's samples, or an image.
void write_output(const RenderArgs& a, const std::optional<lucent::SampleRange>& range,
                  std::optional<lucent::Renderer>& renderer, lucent::RenderResult& r,
                  const lucent::DisplaySettings& display) {
  if (range) {
    r.mean = {};  // (not written: the part's sums are; the rest of r says how it went)
    r.variance = {};
    r.samples = {};
    const lucent::RenderPart part = lucent::make_part(*renderer, *range, a.scene);
    renderer.reset();  // its sums, images and device buffers, before the write's own memory
    lucent::write_render_part(a.output, part);
  } else if (lucent::io::lower_extension(a.output) == ".exr") {
    lucent::write_render_exr(a.output, r);
  } else {
    lucent::write_image(a.output, r.mean, display);
  }
}

int render_with(const RenderArgs& a) {
  // options the reference does not honour: refused, rather than silently ignored (it runs on the
  // CPU, in double precision, with its own code: the kernel's device and build options mean
  // nothing to it)
  if (a.reference) {
    const std::pair<bool, const char*> kernel_only[] = {
        {a.time_limit > 0, "--time"},
        {!a.aovs.empty(), "--aov"},
        {a.sampling.target_error > 0, "--target-error"},
        {!a.device.empty(), "--device"},
        {!a.precision.empty(), "--precision"},
        {a.fast_math, "--fast-math"},
        {a.no_specialize, "--no-specialize"},
        // (its glass does not split: docs/rendering-model.md, "Glass splitting")
        {a.sampling.splits >= 0, "--dielectric-splits"}};
    for (const auto& [given, name] : kernel_only)
      if (given) throw lucent::Error(std::string(name) + " is not supported with --reference");
  }
  // the pilot of an adaptive render: without --target-error there is none
  if (a.sampling.min_spp > 0 && !(a.sampling.target_error > 0))
    throw lucent::Error("--min-spp is the pilot of --target-error: it does nothing without it");
  for (size_t i = 0; i < a.aovs.size(); ++i)  // (one file each: twice would write it twice)
    for (size_t j = 0; j < i; ++j)
      if (a.aovs[i] == a.aovs[j]) throw lucent::Error("--aov " + a.aovs[i] + ": given twice");
  std::optional<lucent::SampleRange> range;  // --samples: a part for `lucent merge`
  if (!a.samples.empty()) {
    range = lucent::parse_sample_range(a.samples);
    if (a.spp > 0) throw lucent::Error("--samples and --spp cannot be combined");
    if (a.reference || !a.aovs.empty() || a.sampling.target_error > 0)
      throw lucent::Error("--samples is not supported with --reference, --aov or --target-error");
    if (lucent::io::lower_extension(a.output) != ".exr")
      throw lucent::Error(a.output + ": --samples writes a part file: use an .exr output");
  }
  if (a.checkpoint_every > 0 && a.checkpoint.empty())
    throw lucent::Error(
        "--checkpoint-every is how often --checkpoint writes: it does nothing "
        "without it");
  if (!a.checkpoint.empty()) {
    // a checkpoint is a part of the samples [0, K): renders that are not one range of samples
    // (adaptive, the reference's pixel by pixel), or whose session lives on (AOVs) or is a part
    const std::pair<bool, const char*> unsupported[] = {
        {range.has_value(), "--samples"},
        {a.reference, "--reference"},
        {!a.aovs.empty(), "--aov"},
        {a.sampling.target_error > 0, "--target-error"}};
    for (const auto& [given, name] : unsupported)
      if (given) throw lucent::Error(std::string("--checkpoint is not supported with ") + name);
    if (lucent::io::lower_extension(a.checkpoint) != ".exr")
      throw lucent::Error(a.checkpoint + ": --checkpoint writes a part file: use an .exr name");
    if (lucent::io::same_file(a.checkpoint, a.output))
      throw lucent::Error(a.checkpoint +
                          ": is the output too: give --checkpoint a file of its own");
  }
  lucent::io::check_output_path(a.output, {a.scene});
  // the outputs against each other (a link made two of them one file, and the last AOV written
  // replaced the other without a word)
  for (size_t i = 0; i < a.aovs.size(); ++i) {
    const std::string path = aov_path(a.output, a.aovs[i]);
    if (lucent::io::same_file(path, a.output))
      throw lucent::Error(path + ": is the output (-o " + a.output +
                          ") too: give each output its own file");
    for (size_t j = 0; j < i; ++j)
      if (lucent::io::same_file(path, aov_path(a.output, a.aovs[j])))
        throw lucent::Error(path + ": is the " + a.aovs[j] + " AOV's output (" +
                            aov_path(a.output, a.aovs[j]) + ") too: give each output its own file");
  }
  for (const std::string& name : a.aovs)
    lucent::io::check_output_path(aov_path(a.output, name), {a.scene, a.output});
  if (!a.checkpoint.empty())
    lucent::io::check_output_path(a.checkpoint, {a.scene, a.output}, /*is_checkpoint=*/true);
  // from here on a stop signal lets the render end its pass and write what it has
  install_stop_handler(on_stop_signal);
  std::signal(SIGPIPE, SIG_IGN);  // a closed stderr pipe must not cost the image
  lucent::Scene scene = lucent::load_scene(a.scene);
  {
    // the files the scene reads (images, meshes) are inputs too
    const std::vector<std::string> inputs = lucent::cli::scene_inputs(a.scene, scene);
    lucent::io::check_output_path(a.output, inputs);
    for (const std::string& name : a.aovs)
      lucent::io::check_output_path(aov_path(a.output, name), inputs);
    if (!a.checkpoint.empty())
      lucent::io::check_output_path(a.checkpoint, inputs, /*is_checkpoint=*/true);
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
  // depths that this render's integrator does not read: refused, rather than ignored without a
  // word (direct is always first-hit emission plus point lights, the AOVs read the first hit,
  // whitted has no Russian roulette)
  using lucent::render_detail::IntegratorKnob;
  lucent::cli::check_knob(scene, a.max_depth > 0, IntegratorKnob::MaxDepth, "--max-depth");
  lucent::cli::check_knob(scene, a.rr_depth > 0, IntegratorKnob::RrDepth, "--rr-depth");
  if (a.max_depth > 0) scene.integrator.max_depth = a.max_depth;
  if (a.rr_depth > 0) scene.integrator.rr_depth = a.rr_depth;
  lucent::cli::apply_sampling_options(a.sampling, scene);
  // values that are not radiance, to an 8-bit image: the display transform and [0, 1] clip them
  // (a depth image of a scene 5 away was a white silhouette, primitive ids white, normals' negative
  // components black), in a file that looks complete
  {
    using lucent::IntegratorType;
    const IntegratorType t = scene.integrator.type;
    const std::string ext = lucent::io::lower_extension(a.output);
    if ((t == IntegratorType::Depth || t == IntegratorType::Normal ||
         t == IntegratorType::Primitive) &&
        ext != ".exr" && ext != ".pfm")  // (a warning: said with -q too)
      std::fprintf(stderr,
                   "lucent: warning: %s: the %s integrator's values are not radiance: an 8-bit "
                   "image clips them to [0, 1] after the film's display transform; write .exr "
                   "or .pfm to keep them\n",
                   one_line(a.output).c_str(), lucent::type_name(t));
  }
  if (range) lucent::check_part_scene(scene, a.scene);
  std::optional<Checkpoint> checkpoint;
  if (!a.checkpoint.empty()) {
    try {
      lucent::check_part_scene(scene, a.scene);
    } catch (const lucent::Error&) {
      throw lucent::Error(a.scene +
                          ": integrator.caustics: a checkpoint (a part file) cannot hold "
                          "light-traced caustics yet; render without --checkpoint, or with "
                          "--no-caustics");
    }
    checkpoint.emplace(a.checkpoint, a.scene,
                       a.checkpoint_every > 0 ? a.checkpoint_every : kDefaultCheckpointSeconds);
    checkpoint->read();
  }

  const OutputMemory memory = output_memory(a, scene.film.width, scene.film.height,
                                            range.has_value(), checkpoint && checkpoint->resumed());

  lucent::RenderOptions opt;
  opt.spp = a.spp;
  opt.time_limit = a.time_limit;
  opt.fast_math = a.fast_math;
  opt.precision = lucent::parse_precision(a.precision.empty() ? "float" : a.precision);
  opt.specialize = !a.no_specialize;
  opt.cancel = &g_interrupted;
  const bool tty = isatty(STDERR_FILENO);
  double last_print = -10;
  bool printed = false;
  // a resumed render: the checkpoint's samples, which its progress line counts ("413 + 1200 spp",
  // its percentage of the whole render; it said "1200 spp", 40% where the image was at 80%)
  const std::uint64_t resumed_from = checkpoint ? checkpoint->first_sample() : 0;
  if (!a.quiet) {
    // short renders stay silent (the stop-signal tests' renders: from the first pass)
    const double progress_start = lucent::cli::early_progress_for_tests() ? 0.0 : 1.0;
    opt.on_progress = [&, progress_start](const lucent::RenderProgress& p) {
      if (p.elapsed < progress_start) return;
      if (!tty && p.elapsed - last_print < 2.0) return;
      last_print = p.elapsed;
      double frac = p.samples_target > 0 ? double(p.samples_done) / double(p.samples_target)
                                         : (p.time_limit > 0 ? p.elapsed / p.time_limit : 0);
      frac = std::min(1.0, frac);
      double eta = frac > 0 ? p.elapsed * (1 - frac) / frac : 0;  // (this run's rate)
      double shown = frac;
      char spp[64];
      if (resumed_from > 0) {
        if (p.samples_target > 0)
          shown = std::min(
              1.0, double(resumed_from + p.samples_done) / double(resumed_from + p.samples_target));
        std::snprintf(spp, sizeof spp, "%llu + %llu", static_cast<unsigned long long>(resumed_from),
                      static_cast<unsigned long long>(p.samples_done));
      } else {
        std::snprintf(spp, sizeof spp, "%llu", static_cast<unsigned long long>(p.samples_done));
      }
      std::fprintf(stderr, "%s%5.1f%%  %s spp  %.2f Msamples/s  elapsed %s  ETA %s%s%s",
                   tty ? "\r" : "", 100 * shown, spp, p.samples_per_second * 1e-6,
                   format_duration(p.elapsed).c_str(), format_duration(eta).c_str(),
                   device_shares(p.devices).c_str(), tty ? "   " : "\n");
      std::fflush(stderr);
      printed = true;
    };
  }
  std::optional<lucent::Renderer> renderer;
  if (checkpoint)  // after each pass: the progress line, then the checkpoint when one is due
    opt.on_progress = [&, print = std::move(opt.on_progress)](const lucent::RenderProgress& p) {
      if (print) print(p);
      checkpoint->on_pass(*renderer);
    };
  // before any device is opened or kernel built: the session's estimate without its devices'
  // parts (set_scene checks it again with them), then the outputs'
  if (!a.reference) {
    std::string what;
    const std::uint64_t limit = lucent::render_detail::host_memory_allowed(&what);
    // (the outputs named as the command line gives them: the library's wording, "what the
    // application keeps beside the session", named no --aov)
    lucent::render_detail::check_host_memory(
        scene, {}, limit, what,
        lucent::render_detail::reserved_part(memory.beside, memory.beside_what), 1);
  }
  if (!memory.after.empty()) lucent::render_detail::check_output_host_memory(scene, memory.after);

  // the session takes the scene (its meshes and textures are not held twice): what is read of it
  // after the render, first
  const lucent::Film film_settings = scene.film;
  const std::uint64_t scene_spp = std::uint64_t(scene.integrator.spp);
  lucent::RenderResult r;
  double wall = 0;  // of the kernel render (several devices: their passes overlap)
  if (a.reference) {
    lucent::ReferenceOptions ro;
    ro.spp = a.spp;
    ro.cancel = &g_interrupted;
    r = lucent::render_reference(scene, ro);
  } else {
    lucent::SessionOptions so = lucent::cli::session_options(a.device);
    so.precision = opt.precision;
    so.fast_math = opt.fast_math;
    so.specialize = opt.specialize;
    so.reserved_host_bytes = memory.beside;
    so.reserved_host_what = memory.beside_what;  // (the session's check names them the same)
    renderer.emplace(so);
    renderer->set_cancel_flag(&g_interrupted);
    auto interrupted_before_rendering = [&] {
      if (printed && tty) std::fprintf(stderr, "\n");
      std::fprintf(stderr, "lucent: interrupted by %s before rendering: nothing written\n",
                   signal_name(g_signal));
      return 128 + g_signal;
    };
    try {
      renderer->set_scene(std::move(scene));
      reclaim_stop_handler(on_stop_signal);  // from PoCL's LLVM (stop_signals.hpp)
      // a stop signal during set_scene (its kernel build, where the build did not fail; its BVH):
      // nothing rendered, and a render call takes at least one pass, which rendered the whole
      // image after the signal and wrote it as "1 of 64 spp"
      if (g_interrupted.load()) return interrupted_before_rendering();
      std::uint64_t spp =
          a.spp > 0 ? static_cast<std::uint64_t>(a.spp) : (a.time_limit > 0 ? 0 : scene_spp);
      if (range) {
        renderer->reset(range->begin);
        spp = range->end - range->begin;
      }
      const bool samples_left = !checkpoint || resume_from(*checkpoint, *renderer, spp, a.quiet);
      auto t0 = std::chrono::steady_clock::now();
      if (a.sampling.target_error > 0)
        renderer->render_adaptive(lucent::cli::adaptive_options(a.sampling, a.spp, a.time_limit),
                                  opt.on_progress);
      else if (samples_left)
        renderer->render(spp, a.time_limit, opt.on_progress);
      wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      r = renderer->result();
    } catch (const lucent::Error&) {
      // a stop signal during the kernel build, where the build failed on it (PoCL's LLVM, when
      // its handlers were in place), or cancelled a wait for another process's build: the
      // interruption, not a build error (it was reported as "kernel build failed", exit 1)
      if (!g_interrupted.load()) throw;
      return interrupted_before_rendering();
    }
  }
  if (printed && tty) std::fprintf(stderr, "\n");
  // this run's samples, rays and time (a resumed render's result becomes the totals of its
  // checkpoint and this run, below): the summary's rates are this run's
  const std::uint64_t run_spp = r.spp, run_rays = r.rays;
  const double run_seconds = r.seconds;
  const std::uint64_t resumed_spp = checkpoint ? checkpoint->first_sample() : 0;
  // a resumed render's image is that of the checkpoint's samples and the session's; its part is
  // kept until the output is written
  std::optional<lucent::RenderPart> kept;
  const bool checkpoint_done =
      checkpoint &&
      finish_checkpoint(*checkpoint, renderer, r, r.cancelled || g_interrupted.load(), kept);
  // interrupted before its first sample (an adaptive render's pilot, the reference's first
  // pixel): no image to write; it wrote a black one claiming "0 of 256 spp". A part keeps its
  // (empty) range, and is written.
  if (!range && g_interrupted.load() && r.nonfinite == 0 &&
      lucent::render_detail::holds_no_sample(r.samples)) {
    std::fprintf(stderr, "lucent: interrupted by %s before the first sample: nothing written\n",
                 signal_name(g_signal));
    return 128 + g_signal;
  }

  lucent::DisplaySettings display{film_settings.transfer, film_settings.gamma,
                                  film_settings.exposure, film_settings.tonemap};
  // every sample non-finite: nothing written (a part keeps its counts, and is written)
  if (!range) lucent::render_detail::check_some_sample_finite(a.output, r.nonfinite, r.samples);
  // the session is not needed again without AOVs: its memory goes before the write's (a part
  // is taken from it first). A complete render's with a checkpoint stays until the output is
  // written: its samples go to the checkpoint should the write fail (the part and its write
  // were counted beside the session, and its result images and the output's write take less)
  if (a.aovs.empty() && !range && !checkpoint_done) renderer.reset();
  try {
    write_output(a, range, renderer, r, display);
  } catch (const lucent::Error& e) {
    if (!checkpoint) throw;
    // a full disk, a directory removed: the samples since the last checkpoint went with the
    // session (up to --checkpoint-every seconds of work), and the checkpoint held an unfinished
    // render although every sample was rendered
    if (!e.details().empty()) std::fprintf(stderr, "%s\n", e.details().c_str());
    std::fprintf(stderr, "lucent: error: %s\n", one_line(e.what()).c_str());
    r = {};  // (its images: the part's write needs the memory)
    keep_samples_of_failed_output(*checkpoint, checkpoint_done, kept, renderer);
    return 1;
  }
  if (a.aovs.empty()) renderer.reset();
  kept.reset();
  // what the checkpoint holds after a render that did not end complete: samples, or none when
  // every write failed (a full disk from the start: the last line said only "wrote out.png with
  // 174 of 2000 spp", the earlier warning alone telling that no checkpoint existed)
  if (checkpoint_done)
    checkpoint->remove();
  else if (checkpoint && (checkpoint->held() > 0 || r.spp > 0))
    say_kept(*checkpoint, false);
  // (a stopped render's pixels without a sample may be the ones it never reached)
  if (r.nonfinite > 0)
    std::fprintf(stderr, "lucent: warning: %s\n",
                 lucent::render_detail::nonfinite_warning(
                     r.nonfinite,
                     r.cancelled || g_interrupted.load() ? std::vector<std::uint32_t>{} : r.samples)
                     .c_str());
  // one device: its pass time; several: the wall time of the render, when they overlapped. A
  // resumed render: this run's time and rates (its spp counts the checkpoint's samples too,
  // which it names: dividing them by this run's wall time gave thousands of Msamples/s)
  double seconds = r.devices.size() > 1 ? wall : run_seconds;
  std::string resumed_note;
  if (resumed_spp > 0)
    resumed_note =
        " (" + std::to_string(resumed_spp) + " of them from " + one_line(checkpoint->path()) + ")";
  // a stopped reference's pixels hold all, some or none of their samples: its spp is their mean,
  // its rate their total (it gave the spp asked for, and a rate made of them). (Not a complete
  // one's: its counts leave out the samples it dropped as non-finite.)
  std::uint64_t shown_spp = r.spp;
  double run_samples = double(run_spp) * film_settings.width * film_settings.height;
  if (a.reference && (r.cancelled || g_interrupted.load()) && !r.samples.empty()) {
    std::uint64_t total = 0;
    for (const std::uint32_t n : r.samples) total += n;
    shown_spp = total / r.samples.size();
    run_samples = double(total);
  }
  if (!a.quiet)
    std::fprintf(
        stderr,
        "%s: %dx%d, %llu spp%s in %.3f s (%.2f Msamples/s, %.2f Mrays/s, build %.2f s, peak "
        "host memory %.0f MiB) on %s%s\n",
        one_line(a.output).c_str(), film_settings.width, film_settings.height,
        static_cast<unsigned long long>(shown_spp), resumed_note.c_str(), seconds,
        seconds > 0 ? run_samples / seconds * 1e-6 : 0,
        seconds > 0 ? double(run_rays) / seconds * 1e-6 : 0, r.build_seconds, peak_host_mib(),
        r.device.c_str(), device_shares(r.devices).c_str());
  // a time limit that ended the render before its plan did (a signal's last line says so)
  std::string stopped_early;
  if (r.plan_incomplete && !r.cancelled && !g_interrupted.load())
    stopped_early = "; the time limit stopped it at " + std::to_string(r.spp) + " of the " +
                    std::to_string(r.planned_spp) + " spp its plan asked for";
  if (!a.quiet && r.target_error > 0 && r.pilot_incomplete)  // (its estimates read a partial pilot)
    std::fprintf(stderr,
                 "%s: adaptive: stopped in its pilot, %llu of %llu spp on average: no plan made, "
                 "the error not estimated (target %.3g)\n",
                 one_line(a.output).c_str(), static_cast<unsigned long long>(r.spp),
                 static_cast<unsigned long long>(r.planned_spp), r.target_error);
  else if (!a.quiet && r.target_error > 0)
    std::fprintf(stderr,
                 "%s: adaptive: %llu spp on average, estimated relMSE %.3g (target %.3g; model "
                 "gains %.3g, %.3g), from the halves' difference %.3g%s\n",
                 one_line(a.output).c_str(), static_cast<unsigned long long>(r.spp),
                 r.estimated_relmse, r.target_error, r.model_gain_a, r.model_gain_b,
                 r.halves_relmse, stopped_early.c_str());
  // a uniform render of --spp N that --time stopped short: said as the adaptive one says it (the
  // summary's "2651 spp" did not say of what, and the status is 0: the limit was asked for)
  if (!a.quiet && !(r.target_error > 0) && a.time_limit > 0 && a.spp > 0 &&
      r.spp < std::uint64_t(a.spp) && !r.cancelled && !g_interrupted.load())
    std::fprintf(stderr, "%s: the time limit stopped it at %llu of the %llu spp asked for\n",
                 one_line(a.output).c_str(), static_cast<unsigned long long>(r.spp),
                 static_cast<unsigned long long>(a.spp));
  if (std::string s = lucent::target_shortfall(r); !s.empty())
    std::fprintf(stderr, "lucent: warning: %s: %s\n", one_line(a.output).c_str(), s.c_str());
  std::vector<std::string> missing_aovs;
  if (!a.reference) missing_aovs = write_aovs(a, &*renderer, r);
  if (r.cancelled || g_interrupted.load()) {
    const int sig = g_signal ? static_cast<int>(g_signal) : SIGINT;
    std::uint64_t target = a.spp > 0 ? std::uint64_t(a.spp) : (a.time_limit > 0 ? 0 : scene_spp);
    if (range) target = range->end - range->begin;
    std::string aovs;  // the AOVs asked for and not written
    for (const std::string& name : missing_aovs)
      aovs += (aovs.empty() ? " (AOVs not written: " : ", ") + name;
    if (!aovs.empty()) aovs += ")";
    std::fprintf(stderr, "lucent: interrupted by %s: wrote %s with %s%s\n", signal_name(sig),
                 one_line(a.output).c_str(),
                 progress_note(r, target, a.time_limit, a.reference).c_str(), aovs.c_str());
    if (range)
      std::fprintf(stderr, "lucent: %s holds samples [%llu, %llu) of %s\n",
                   one_line(a.output).c_str(), static_cast<unsigned long long>(range->begin),
                   static_cast<unsigned long long>(range->begin + r.spp),
                   lucent::range_text(*range).c_str());
    return 128 + sig;
  }
  return 0;
}

RenderArgs& render_args() {
  static RenderArgs a;
  return a;
}

}  // namespace

const std::string& render_scene() { return render_args().scene; }

CLI::App* add_render_command(CLI::App& app) {
  RenderArgs& ra = render_args();
  CLI::App* render = app.add_subcommand("render", "Render a JSON scene to an image");
  render->add_option("scene", ra.scene, "Scene file (JSON)")
      ->required()
      ->check(lucent::cli::non_empty());
  render
      ->add_option(
          "-o,--output", ra.output,
          "Output image: .png (8-bit, the film's transfer, exposure and tone map), .pfm or .exr "
          "(linear)")
      ->required()
      ->check(lucent::cli::non_empty());
  render
      ->add_option("--spp", ra.spp,
                   "Samples per pixel (default: the scene's integrator.spp; with --time alone, as "
                   "many as the time allows; with --target-error the most per pixel, default "
                   "16384)")
      ->check(CLI::Range(1, lucent::limits::kMaxSpp));
  render
      ->add_option("--time", ra.time_limit,
                   "Stop after this many seconds of rendering (alone: render until then; "
                   "--aov images then render as many samples, after it)")
      ->check(lucent::cli::seconds_limit());
  render->add_option("--width", ra.width, "Image width (overrides the scene)")
      ->check(CLI::Range(1, lucent::limits::kMaxImageSize));
  render->add_option("--height", ra.height, "Image height (overrides the scene)")
      ->check(CLI::Range(1, lucent::limits::kMaxImageSize));
  render
      ->add_option("--device", ra.device,
                   "OpenCL device: index or name substring, a comma-separated list of them or "
                   "'all' to share the render (env LUCENT_DEVICE)")
      ->check(lucent::cli::non_empty());
  render->add_option("--seed", ra.seed, "Random seed (overrides the scene)")
      ->check(CLI::Range(0LL, static_cast<long long>(lucent::limits::kMaxSeed)));
  render
      ->add_option("--integrator", ra.integrator,
                   "Override the integrator: " + lucent::type_names<lucent::IntegratorType>())
      ->check(lucent::cli::non_empty());
  render
      ->add_option("--max-depth", ra.max_depth,
                   "Most path segments: 1 shows the emitters the camera sees, 2 adds direct "
                   "light (overrides integrator.max_depth)")
      ->check(CLI::Range(1, lucent::limits::kMaxDepth));
  render
      ->add_option("--rr-depth", ra.rr_depth,
                   "Path segments before Russian roulette may end a path (overrides "
                   "integrator.rr_depth)")
      ->check(CLI::Range(1, lucent::limits::kMaxDepth));
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
                   "Also write AOV images <stem>.<name>.exr: " +
                       lucent::cli::joined(lucent::cli::aov_names()))
      ->delimiter(',')
      ->check(CLI::IsMember(lucent::cli::aov_names()));
  render
      ->add_option("--samples", ra.samples,
                   "Render only the sample indices [A, B) (A:B) and write their raw "
                   "accumulation to an .exr part file for `lucent merge`")
      ->check(lucent::cli::non_empty());
  render
      ->add_option("--checkpoint", ra.checkpoint,
                   "Write the samples rendered so far to this .exr part file every "
                   "--checkpoint-every seconds, and resume from it when it exists; removed "
                   "once the output is written (docs/parts.md, \"Checkpoints\")")
      ->check(lucent::cli::non_empty());
  render
      ->add_option("--checkpoint-every", ra.checkpoint_every,
                   "Seconds between two checkpoints (default 300)")
      ->check(lucent::cli::seconds_limit());
  render->add_flag("--reference", ra.reference,
                   "Render with the scalar CPU reference integrator instead of the kernel");
  lucent::cli::add_sampling_options(render, ra.sampling, true);

  return render;
}

int run_render_command() { return render_with(render_args()); }

}  // namespace lucent::cli
