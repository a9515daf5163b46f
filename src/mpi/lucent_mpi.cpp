// `mpirun -np K lucent-mpi SCENE -o OUT`: one render split over MPI ranks. Rank r renders the
// sample indices [N r / K, N (r + 1) / K) of the N samples per pixel, then rank 0 receives the
// ranks' raw accumulations in rank order (ascending sample ranges), adds them with
// lucent::PartMerger (the code of `lucent merge`, so the image is the merge of the ranks' parts)
// and writes OUT atomically. A rank that fails prints one line naming it and ends the job with
// MPI_Abort: nothing is written. SIGINT, SIGTERM and SIGHUP stop every rank after its current
// pass; what they rendered is merged and written (an .exr records the ranges it holds).
#include <mpi.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/file_io.hpp"
#include "core/text.hpp"
#include "image/image_probe.hpp"
#include "lucent/limits.hpp"
#include "lucent/lucent.hpp"
#include "lucent/parts.hpp"
#include "lucent/types.hpp"
#include "render/resources.hpp"
#include "scene/loaders.hpp"

namespace {

using lucent::io::one_line;

std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_stop_signal(int sig) {
  g_signal = sig;
  g_stop.store(true);
  std::signal(sig, SIG_DFL);  // a second signal ends the rank at once, as with lucent render
}

int g_rank = 0, g_size = 1;

/// One line naming the rank, then the whole job ends: no rank writes anything after this.
[[noreturn]] void fail(const std::string& what) {
  char host[256] = "?";
  gethostname(host, sizeof host - 1);
  std::fprintf(stderr, "lucent-mpi: error: rank %d of %d (%s): %s\n", g_rank, g_size, host,
               one_line(what).c_str());
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, 1);
  std::_Exit(1);  // not reached
}

struct Args {
  std::string scene, output, device, precision = "float";
  int spp = 0, width = 0, height = 0;
  long long seed = -1;
  double time_limit = 0;
  bool fast_math = false, quiet = false;
};

// What travels from a rank to rank 0 besides its sums: the part's header.
struct Header {
  std::uint64_t width, height, hash, seed, begin, end, req_begin, req_end, nonfinite, rays;
  double seconds;
  char integrator[32];
};

void send_part(const lucent::RenderPart& p) {
  Header h{};
  h.width = p.info.width;
  h.height = p.info.height;
  h.hash = p.info.scene_hash;
  h.seed = p.info.seed;
  if (!p.info.samples.empty()) h.begin = p.info.samples[0].begin, h.end = p.info.samples[0].end;
  h.req_begin = p.info.requested[0].begin;
  h.req_end = p.info.requested[0].end;
  h.nonfinite = p.info.nonfinite;
  h.rays = p.info.rays;
  h.seconds = p.info.seconds;
  std::strncpy(h.integrator, p.info.integrator.c_str(), sizeof h.integrator - 1);
  MPI_Send(&h, sizeof h, MPI_BYTE, 0, 0, MPI_COMM_WORLD);
  MPI_Send(p.acc.sum.data(), static_cast<int>(p.acc.sum.size()), MPI_DOUBLE, 0, 1, MPI_COMM_WORLD);
  MPI_Send(p.acc.sumsq.data(), static_cast<int>(p.acc.sumsq.size()), MPI_DOUBLE, 0, 2,
           MPI_COMM_WORLD);
  MPI_Send(p.acc.count.data(), static_cast<int>(p.acc.count.size()), MPI_UINT32_T, 0, 3,
           MPI_COMM_WORLD);
}

/// Rank `from`'s part; the header fields that are not sent (display, version, scene) are
/// rank 0's.
lucent::RenderPart receive_part(int from, const lucent::PartInfo& mine,
                                const lucent::SampleRange& expected) {
  Header h{};
  MPI_Recv(&h, sizeof h, MPI_BYTE, from, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  if (h.width != std::uint64_t(mine.width) || h.height != std::uint64_t(mine.height))
    fail("rank " + std::to_string(from) + " rendered a " + std::to_string(h.width) + "x" +
         std::to_string(h.height) + " film, rank 0 " + std::to_string(mine.width) + "x" +
         std::to_string(mine.height));
  // its share of rank 0's samples per pixel (another --spp made a merge with a gap, exit 0)
  if (h.req_begin != expected.begin || h.req_end != expected.end)
    fail("rank " + std::to_string(from) + " was given samples " +
         lucent::range_text({h.req_begin, h.req_end}) + ", its share of rank 0's is " +
         lucent::range_text(expected) + " (another --spp?)");
  lucent::RenderPart p;
  p.info = mine;
  p.info.scene_hash = h.hash;
  p.info.seed = static_cast<std::uint32_t>(h.seed);
  p.info.samples.clear();
  if (h.end > h.begin) p.info.samples.push_back({h.begin, h.end});
  p.info.requested = {{h.req_begin, h.req_end}};
  p.info.nonfinite = h.nonfinite;
  p.info.rays = h.rays;
  p.info.seconds = h.seconds;
  h.integrator[sizeof h.integrator - 1] = 0;
  p.info.integrator = h.integrator;
  const size_t npix = static_cast<size_t>(mine.width) * mine.height;
  p.acc.width = mine.width;
  p.acc.height = mine.height;
  p.acc.sum.resize(npix * 3);
  p.acc.sumsq.resize(npix * 3);
  p.acc.count.resize(npix);
  MPI_Recv(p.acc.sum.data(), static_cast<int>(npix * 3), MPI_DOUBLE, from, 1, MPI_COMM_WORLD,
           MPI_STATUS_IGNORE);
  MPI_Recv(p.acc.sumsq.data(), static_cast<int>(npix * 3), MPI_DOUBLE, from, 2, MPI_COMM_WORLD,
           MPI_STATUS_IGNORE);
  MPI_Recv(p.acc.count.data(), static_cast<int>(npix), MPI_UINT32_T, from, 3, MPI_COMM_WORLD,
           MPI_STATUS_IGNORE);
  return p;
}

int run(const Args& a) {
  const bool root = g_rank == 0;
  if (root) lucent::io::check_output_path(a.output, {a.scene});
  lucent::Scene scene = lucent::load_scene(a.scene);
  if (a.width > 0) scene.film.width = a.width;
  if (a.height > 0) scene.film.height = a.height;
  if (a.seed >= 0) scene.integrator.seed = static_cast<std::uint32_t>(a.seed);
  // nor a file the scene reads (a texture or mesh: rank 0 replaced it)
  if (root)
    lucent::io::check_output_path(a.output, lucent::scene_detail::scene_inputs(a.scene, scene));
  lucent::check_part_scene(scene, a.scene);
  const std::uint64_t n = a.spp > 0 ? std::uint64_t(a.spp) : scene.integrator.spp;
  if (n < std::uint64_t(g_size))
    throw lucent::Error(std::to_string(g_size) + " ranks for " + std::to_string(n) +
                        " samples per pixel: use at most one rank per sample");
  // rank r's share of the samples [0, n)
  auto share = [&](int r) {
    return lucent::SampleRange{n * std::uint64_t(r) / g_size, n * std::uint64_t(r + 1) / g_size};
  };
  const lucent::SampleRange range = share(g_rank);

  // memory beside the session: each rank's part, copied from it before it goes; then on rank 0
  // its part, the merge, a part received and the write (refused now rather than after the render)
  const int fw = scene.film.width, fh = scene.film.height;
  const std::uint64_t npix = std::uint64_t(fw) * std::uint64_t(fh);
  const std::uint64_t part_bytes = npix * lucent::render_detail::kAccumulationPixelBytes;
  if (root) {
    const std::string film = std::to_string(fw) + "x" + std::to_string(fh);
    const std::uint64_t write = lucent::io::lower_extension(a.output) == ".exr"
                                    ? lucent::part_write_bytes(fw, fh)
                                    : npix * lucent::render_detail::kResultPixelBytes +
                                          lucent::image_detail::image_write_bytes(a.output, fw, fh);
    lucent::render_detail::check_output_host_memory(
        scene, {{"rank 0's part, the merged sums and a part received of the " + film + " film",
                 3 * part_bytes, "the film size"},
                {"writing " + one_line(a.output) + " (" + film + ")", write, "the film size"}});
  }

  lucent::SessionOptions so = lucent::SessionOptions::from_environment();
  so.reserved_host_bytes = part_bytes;
  if (!a.device.empty()) so.device = a.device;
  so.precision = lucent::parse_precision(a.precision);
  so.fast_math = a.fast_math;
  std::optional<lucent::Renderer> session(std::in_place, so);
  lucent::Renderer& renderer = *session;
  renderer.set_cancel_flag(&g_stop);
  renderer.set_scene(std::move(scene));  // held once, by the session
  renderer.reset(range.begin);
  const bool tty = isatty(STDERR_FILENO);
  double last = -10;
  auto progress = [&](const lucent::RenderProgress& p) {
    if (!root || a.quiet || p.elapsed < 1.0 || (!tty && p.elapsed - last < 2.0)) return;
    last = p.elapsed;
    std::fprintf(stderr, "%srank 0 of %d: %5.1f%%  %llu of %llu spp  %.2f Msamples/s%s",
                 tty ? "\r" : "", g_size, 100.0 * double(p.samples_done) / double(p.samples_target),
                 static_cast<unsigned long long>(p.samples_done),
                 static_cast<unsigned long long>(p.samples_target), p.samples_per_second * 1e-6,
                 tty ? "   " : "\n");
  };
  renderer.render(range.end - range.begin, a.time_limit, progress);
  if (root && !a.quiet && last > 0 && tty) std::fprintf(stderr, "\n");
  lucent::RenderPart part = lucent::make_part(renderer, range, a.scene);
  session.reset();  // its sums and device buffers: the part is what is sent, merged and written

  if (!root) {
    send_part(part);
    return 0;
  }
  lucent::PartMerger merger;
  merger.add("rank 0", part);
  for (int r = 1; r < g_size; ++r) {
    lucent::RenderPart p = receive_part(r, part.info, share(r));
    try {
      merger.add("rank " + std::to_string(r), p);
    } catch (const lucent::Error& e) {
      fail(e.what());
    }
  }
  lucent::MergeReport m = merger.finish();
  lucent::write_merged(a.output, m.merged);
  if (!a.quiet)
    std::fprintf(stderr, "%s: %dx%d, samples %s from %d ranks (%.2f s of kernel time in all)\n",
                 one_line(a.output).c_str(), m.merged.info.width, m.merged.info.height,
                 lucent::ranges_text(m.merged.info.samples).c_str(), g_size, m.merged.info.seconds);
  if (m.merged.info.nonfinite > 0)
    std::fprintf(stderr,
                 "lucent-mpi: warning: %llu non-finite sample(s) (NaN or Inf) were dropped\n",
                 static_cast<unsigned long long>(m.merged.info.nonfinite));
  if (g_stop.load()) {
    std::fprintf(stderr, "lucent-mpi: interrupted: %s holds samples %s of [0, %llu)\n",
                 one_line(a.output).c_str(), lucent::ranges_text(m.merged.info.samples).c_str(),
                 static_cast<unsigned long long>(n));
    return 128 + (g_signal ? int(g_signal) : SIGINT);
  }
  // a rank stopped early (a signal to that rank alone) without --time: the image is written,
  // with fewer samples than asked, which it said nothing about (exit 0, and a PNG looks
  // complete)
  const std::vector<lucent::SampleRange> missing =
      lucent::missing_ranges(m.merged.info.samples, {0, n});
  if (!missing.empty() && !(a.time_limit > 0)) {
    std::fprintf(stderr,
                 "lucent-mpi: error: %s holds samples %s of [0, %llu): samples %s are missing (a "
                 "rank stopped early)\n",
                 one_line(a.output).c_str(), lucent::ranges_text(m.merged.info.samples).c_str(),
                 static_cast<unsigned long long>(n), lucent::ranges_text(missing).c_str());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, on_stop_signal);

  Args a;
  CLI::App app{
      "lucent-mpi: one render split over MPI ranks (mpirun -np K lucent-mpi SCENE -o OUT)"};
  app.set_version_flag("--version", std::string("lucent-mpi ") + lucent::kVersion);
  app.add_option("scene", a.scene, "Scene file (JSON)")->required();
  app.add_option("-o,--output", a.output, "Output: .exr (a part file), .png or .pfm")->required();
  app.add_option("--spp", a.spp, "Samples per pixel in all (default: the scene's)")
      ->check(CLI::Range(1, lucent::limits::kMaxSpp));
  // as `lucent render --time`: a finite number of seconds up to 1e7 (CLI::PositiveNumber let NaN
  // through to a rank's MPI_Abort, and refused inf naming 1.8e308 in 300 digits)
  app.add_option("--time", a.time_limit, "Each rank stops after this many seconds (at most 1e7)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            double v = 0;
            if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v))
              return "must be a finite number of seconds, got " + text;
            return v > 0 && v <= 1e7 ? "" : "must be in (0, 1e7] seconds, got " + text;
          },
          "SECONDS"));
  app.add_option("--width", a.width, "Image width")
      ->check(CLI::Range(1, lucent::limits::kMaxImageSize));
  app.add_option("--height", a.height, "Image height")
      ->check(CLI::Range(1, lucent::limits::kMaxImageSize));
  app.add_option("--seed", a.seed, "Random seed")
      ->check(CLI::Range(0LL, static_cast<long long>(lucent::limits::kMaxSeed)));
  app.add_option("--device", a.device, "OpenCL device(s) of every rank (env LUCENT_DEVICE)");
  app.add_option("--precision", a.precision, "float or double")
      ->check(CLI::IsMember({"float", "double"}));
  app.add_flag("--fast-math", a.fast_math, "Build the kernel with -cl-fast-relaxed-math");
  app.add_flag("-q,--quiet", a.quiet, "No progress line or summary");
  // the ranks agree on whether the arguments parse: a rank that ended alone on a parse error
  // (different arguments per rank, mpirun's A : B) left rank 0 waiting for its part for ever
  int failed = 0, parse_status = 0, code = 0;
  std::string message;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    failed = 1;
    code = e.get_exit_code();
    if (g_rank != 0) {
      message = e.what();
    } else if (code == 0) {
      parse_status = app.exit(e);  // --help, --version: stdout, status 0
    } else {
      // one line and status 2, as `lucent` says it (CLI11's own exit printed two lines and
      // exited 105, 106 or 109)
      std::string what = e.what();
      for (char& c : what)
        if (c == '\n') c = ' ';
      std::fprintf(stderr, "lucent-mpi: error: %s (see lucent-mpi --help)\n",
                   one_line(what).c_str());
      parse_status = 2;
    }
  }
  int root_failed = failed, any_failed = 0;
  MPI_Bcast(&root_failed, 1, MPI_INT, 0, MPI_COMM_WORLD);
  MPI_Allreduce(&failed, &any_failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (any_failed) {
    if (failed && !root_failed)
      std::fprintf(stderr,
                   "lucent-mpi: error: rank %d of %d: %s (its arguments are not rank 0's)\n",
                   g_rank, g_size, one_line(message).c_str());
    MPI_Finalize();
    if (!failed || (!root_failed && g_rank != 0)) return 2;
    return parse_status ? parse_status : (code ? 2 : 0);
  }
  int status = 0;
  try {
    status = run(a);
  } catch (const std::exception& e) {
    fail(e.what());
  }
  MPI_Finalize();
  return status;
}
