// `mpirun -np K lucent-mpi SCENE -o OUT`: one render split over MPI ranks. Rank r renders the
// sample indices [N r / K, N (r + 1) / K) of the N samples per pixel, then rank 0 receives the
// ranks' raw accumulations in rank order (ascending sample ranges), adds them with
// lucent::PartMerger (the code of `lucent merge`, so the image is the merge of the ranks' parts)
// and writes OUT atomically. Failures before rendering (the scene, the device, the kernel build,
// the checkpoints) are agreed by the ranks: the lowest failing rank prints one line naming it,
// every rank exits 1. A rank that fails later prints one line and ends the job with MPI_Abort.
// Either way nothing is written. SIGINT, SIGTERM and SIGHUP stop every rank after its current
// pass, also when one rank alone has the signal (the ranks agree on it while they render:
// StopAgreement); what they rendered is merged and written (an .exr records the ranges it holds).
// --checkpoint CK: each rank keeps a checkpoint of its own range, CK with ".rank<r>-of-<K>" before
// its extension (src/cli/checkpoint.hpp, as `lucent render --checkpoint`), resumed by the same
// command with the same number of ranks (docs/parts.md, "Checkpoints of lucent-mpi").
#include <mpi.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cl/context.hpp"
#include "cli/checkpoint.hpp"
#include "cli/option_checks.hpp"
#include "cli/progress_start.hpp"
#include "cli/stop_signals.hpp"
#include "core/file_io.hpp"
#include "core/text.hpp"
#include "image/image_probe.hpp"
#include "lucent/limits.hpp"
#include "lucent/lucent.hpp"
#include "lucent/parts.hpp"
#include "lucent/types.hpp"
#include "render/resources.hpp"
#include "render/sample_stats.hpp"
#include "scene/loaders.hpp"

namespace {

using lucent::io::one_line;

std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_stop_signal(int sig) {
  // a second signal from a second after the first ends the rank at once, as lucent's
  // (stop_signals.hpp)
  if (!lucent::cli::first_stop_signal(sig)) return;
  g_signal = sig;
  g_stop.store(true);
}

int g_rank = 0, g_size = 1;

/// "lucent-mpi: error: rank 1 of 4 (node17): WHAT".
/// `details`: the error's own lines (lucent::Error::details(): a kernel build's log, which the
/// line refers to as "build log above"), printed before the line as `lucent` prints them.
void print_failure(const std::string& what, const std::string& details = "") {
  char host[256] = "?";
  gethostname(host, sizeof host - 1);
  if (!details.empty()) std::fprintf(stderr, "%s\n", details.c_str());
  std::fprintf(stderr, "lucent-mpi: error: rank %d of %d (%s): %s\n", g_rank, g_size, host,
               one_line(what).c_str());
  std::fflush(stderr);
}

/// One line naming the rank, then the whole job ends: no rank writes anything after this.
[[noreturn]] void fail(const std::string& what, const std::string& details = "") {
  print_failure(what, details);
  MPI_Abort(MPI_COMM_WORLD, 1);
  std::_Exit(1);  // not reached
}

/// Warnings (the scene's, the session's): rank 0 prints its own as they come; the other ranks
/// hold theirs until share_warnings() sends them to rank 0, which prints those it has not
/// printed, once, naming the first rank that gave each. Every rank loads the same scene, and a
/// job printed each of its warnings once per rank.
std::mutex g_warnings_mutex;
std::vector<std::string> g_warnings;  // another rank's, held (as one line each)
std::set<std::string> g_printed;      // rank 0's, printed (as one line each)

void on_warning(const std::string& message) {
  const std::string line = one_line(message);  // (as the other ranks send it)
  std::lock_guard<std::mutex> lock(g_warnings_mutex);
  if (g_rank != 0) {
    g_warnings.push_back(line);
  } else if (g_printed.insert(line).second) {
    std::fprintf(stderr, "lucent: warning: %s\n", line.c_str());
    std::fflush(stderr);
  }
}

/// Collective: the other ranks' held warnings, to rank 0 (see on_warning).
void share_warnings() {
  std::string mine;
  {
    std::lock_guard<std::mutex> lock(g_warnings_mutex);
    if (g_rank != 0)
      for (const std::string& w : g_warnings) mine += w + '\n';
    g_warnings.clear();
  }
  const int length = static_cast<int>(std::min<std::size_t>(mine.size(), 1 << 20));
  std::vector<int> lengths(g_rank == 0 ? g_size : 0), at(g_rank == 0 ? g_size : 0);
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::string all;
  if (g_rank == 0) {
    std::size_t total = 0;
    for (int r = 0; r < g_size; ++r) at[r] = static_cast<int>(total), total += lengths[r];
    all.resize(total);
  }
  MPI_Gatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), at.data(), MPI_CHAR, 0,
              MPI_COMM_WORLD);
  if (g_rank != 0) return;
  std::lock_guard<std::mutex> lock(g_warnings_mutex);
  for (int r = 1; r < g_size; ++r) {
    std::size_t from = at[r];
    const std::size_t end = from + lengths[r];
    while (from < end) {
      std::size_t eol = all.find('\n', from);
      if (eol == std::string::npos || eol > end) eol = end;
      const std::string w = all.substr(from, eol - from);
      from = eol + 1;
      if (w.empty() || !g_printed.insert(w).second) continue;
      std::fprintf(stderr, "lucent: warning: rank %d of %d: %s\n", r, g_size, w.c_str());
    }
  }
  std::fflush(stderr);
}

/// A step every rank takes, whose failure on any rank stops them all: the lowest failing rank
/// prints its line (as fail() does) and every rank gets true, to end with status 1. One line,
/// where a check that fails on every rank (a checkpoint of another seed) printed one per rank
/// before the first MPI_Abort ended the job.
bool refused(const std::function<void()>& step) {
  std::string what, details;
  int mine = g_size, first = g_size;
  try {
    step();
  } catch (const lucent::Error& e) {
    what = e.what();
    details = e.details();
    mine = g_rank;
  } catch (const std::exception& e) {
    what = e.what();
    mine = g_rank;
  }
  share_warnings();  // (before the failure's line: what led to it)
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == g_rank) print_failure(what, details);
  return first < g_size;
}

/// The ranks' agreement on a stop while they render, so that a stop signal to one rank (a node
/// drained, or the signal reaching the ranks at different times) stops every rank within a few
/// passes: the other ranks rendered their whole share (or to their --time) before the agreement
/// after the render, hours on a cluster. Rounds of MPI_Iallreduce: each rank contributes
/// whether it has a stop signal and whether it still renders, and posts the next round when one
/// completes. A round that says a rank is stopped ends the rounds and cancels every rank's render
/// after its current pass; one that says no rank renders any more ends them too. Every rank sees
/// each round's same result, so every rank posts the same rounds (the MPI rule for collectives).
/// A rank polls from its render's progress callback (poll(): after each pass), then, its render
/// ended, until the rounds end (finish()): a rank that finished its share takes part until then,
/// and its own signal during that wait stops the others too.
class StopAgreement {
 public:
  /// Posts the first round. `rendering`: this rank has samples to render.
  /// `any_thread`: MPI may be called from a thread other than the main one, one at a time
  /// (MPI_THREAD_SERIALIZED): the progress callback of a render on several devices runs on the
  /// devices' threads (one at a time, under the session's lock); without it only the main
  /// thread's callbacks poll, and a rank rendering on several devices takes no part in the rounds
  /// until its render ends: every round, and so a stop on any rank, waits for it.
  StopAgreement(bool rendering, bool any_thread)
      : any_thread_(any_thread), main_(std::this_thread::get_id()) {
    post(rendering);
  }
  StopAgreement(const StopAgreement&) = delete;
  StopAgreement& operator=(const StopAgreement&) = delete;

  /// From the render's progress callback: true once the ranks have agreed on a stop (the caller
  /// then cancels its render). Never waits.
  bool poll() {
    if (stop_) return true;
    if (over_ || (!any_thread_ && std::this_thread::get_id() != main_)) return false;
    // (a few rounds at most: each needs every rank's post, which another rank makes at its own
    // pass boundary or, its render ended, within a millisecond)
    for (int i = 0; i < 4 && step(/*rendering=*/true); ++i) {
    }
    return stop_;
  }

  /// After the render (also when it rendered nothing): takes part in the rounds until they end.
  /// (Which signal stopped which rank is agreed after it, by the ranks' own MPI_Allreduce.)
  void finish() {
    while (!over_) {
      if (!step(/*rendering=*/false)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }

  /// The rounds completed: 2 or more once every rank has posted from a pass's end (poll) or from
  /// the end of its render (finish), the first round being posted before any renders.
  int rounds() const { return rounds_; }

 private:
  /// Posts a round of this rank's state.
  void post(bool rendering) {
    mine_[0] = g_stop.load() ? 1 : 0;
    mine_[1] = rendering ? 1 : 0;
    MPI_Iallreduce(mine_, all_, 2, MPI_INT, MPI_MAX, MPI_COMM_WORLD, &request_);
  }
  /// Tests the round posted; when it is complete, ends the rounds or posts the next. True when a
  /// round completed.
  bool step(bool rendering) {
    int done = 0;
    MPI_Test(&request_, &done, MPI_STATUS_IGNORE);
    if (!done) return false;
    ++rounds_;
    if (all_[0] > 0) {
      stop_ = over_ = true;
    } else if (all_[1] == 0) {
      over_ = true;  // no rank renders: the render is over, no stop among the rounds
    } else {
      post(rendering);
    }
    return true;
  }

  const bool any_thread_;
  const std::thread::id main_;
  int mine_[2] = {0, 0}, all_[2] = {0, 0};
  MPI_Request request_ = MPI_REQUEST_NULL;
  bool stop_ = false, over_ = false;
  int rounds_ = 0;
};

/// Whether MPI may be called from any thread, one at a time (MPI_Init_thread's answer).
bool g_mpi_any_thread = false;

/// Whether a rank has a stop signal, agreed by all ranks: its number (the highest any rank has),
/// else 0. The lowest stopped rank says so, in one line.
int stopped_before_rendering() {
  const int mine = g_stop.load() ? (g_signal ? int(g_signal) : SIGINT) : 0;
  int sig = 0, first = g_size;
  const int rank = mine ? g_rank : g_size;
  MPI_Allreduce(&mine, &sig, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(&rank, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == g_rank)
    std::fprintf(stderr,
                 "lucent-mpi: rank %d of %d: interrupted by %s before rendering: nothing written\n",
                 g_rank, g_size, lucent::cli::signal_name(mine));
  return sig;
}

struct Args {
  std::string scene, output, device, precision = "float";
  int spp = 0, width = 0, height = 0;
  long long seed = -1;
  double time_limit = 0;
  bool fast_math = false, quiet = false;
  bool no_caustics = false;     ///< integrator.caustics off (ranks cannot hold light tracing's)
  std::string checkpoint;       ///< CK: each rank's checkpoint is rank_checkpoint(CK, r, K)
  double checkpoint_every = 0;  ///< seconds; 0: not given
};

/// Rank r of K's checkpoint: CK's name with ".rank<r>-of-<K>" before its extension
/// (ck.exr: ck.rank3-of-8.exr), beside it. K is in the name: a run with another number of ranks
/// splits the samples otherwise, and finds the other run's files by it (refuse_other_rank_counts).
std::string rank_checkpoint(const std::string& ck, int rank, int ranks) {
  const std::filesystem::path p(ck);
  return (p.parent_path() / (p.stem().string() + ".rank" + std::to_string(rank) + "-of-" +
                             std::to_string(ranks) + p.extension().string()))
      .string();
}

/// "ck.rank<r>-of-4.exr": the names of the K ranks' checkpoints, for messages.
std::string rank_checkpoints(const std::string& ck, int ranks) {
  const std::filesystem::path p(ck);
  return (p.parent_path() /
          (p.stem().string() + ".rank<r>-of-" + std::to_string(ranks) + p.extension().string()))
      .string();
}

/// Refuses the checkpoints of a run with another number of ranks beside CK (its ranks' shares
/// are other ranges, which this run's ranks cannot resume): "ck.rank0-of-2.exr: a checkpoint of
/// a run of 2 ranks, ...". Rank 0's check, before any rank locks or reads its own.
void refuse_other_rank_counts(const std::string& ck, int ranks) {
  const std::filesystem::path p(ck);
  const std::filesystem::path dir = p.has_parent_path() ? p.parent_path() : ".";
  const std::string head = p.stem().string() + ".rank", ext = p.extension().string();
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= head.size() + ext.size() || name.compare(0, head.size(), head) != 0 ||
        name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
      continue;
    // "<r>-of-<k>" between them, digits only
    const std::string mid = name.substr(head.size(), name.size() - head.size() - ext.size());
    const size_t of = mid.find("-of-");
    auto digits = [](const std::string& t) {
      return !t.empty() && t.size() < 10 &&
             std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    };
    if (of == std::string::npos || !digits(mid.substr(0, of)) || !digits(mid.substr(of + 4)))
      continue;
    const int k = std::stoi(mid.substr(of + 4));
    if (k == ranks) continue;
    // the files to remove: the checkpoints and their locks (ck.rank*-of-2.exr*), and the
    // temporary files of a write killed half-way (.ck.rank*-of-2.exr.tmp-*, hidden, which a
    // run of 2 ranks removes but this one cannot: "ck.rank*-of-2.exr" left both for ever)
    const std::string base = p.stem().string() + ".rank*-of-" + std::to_string(k) + ext;
    const std::string files = (p.parent_path() / (base + "*")).string() + " and " +
                              (p.parent_path() / ("." + base + ".tmp-*")).string();
    throw lucent::Error((p.parent_path() / name).string() + ": a checkpoint of a run of " +
                        std::to_string(k) + " ranks, this one has " + std::to_string(ranks) +
                        ": resume it with mpirun -np " + std::to_string(k) + ", or remove " +
                        files + " to start again");
  }
}

// What travels from a rank to rank 0 besides its sums: the part's header.
struct Header {
  std::uint64_t width, height, hash, seed, begin, end, req_begin, req_end, nonfinite, rays;
  double seconds;
  char integrator[32];
};

Header to_header(const lucent::PartInfo& info) {
  Header h{};
  h.width = info.width;
  h.height = info.height;
  h.hash = info.scene_hash;
  h.seed = info.seed;
  if (!info.samples.empty()) h.begin = info.samples[0].begin, h.end = info.samples[0].end;
  h.req_begin = info.requested[0].begin;
  h.req_end = info.requested[0].end;
  h.nonfinite = info.nonfinite;
  h.rays = info.rays;
  h.seconds = info.seconds;
  std::strncpy(h.integrator, info.integrator.c_str(), sizeof h.integrator - 1);
  return h;
}

/// Rank `from`'s header `h` as a PartInfo, its film and its share checked against rank 0's
/// (`mine`, whose share for `from` is `expected`); the rest (seed, integrator, scene hash) is
/// PartMerger's to check. The fields that are not sent (display, version, scene) are rank 0's.
lucent::PartInfo check_header(Header h, int from, const lucent::PartInfo& mine,
                              const lucent::SampleRange& expected) {
  if (h.width != std::uint64_t(mine.width) || h.height != std::uint64_t(mine.height))
    throw lucent::Error("rank " + std::to_string(from) + " renders a " + std::to_string(h.width) +
                        "x" + std::to_string(h.height) + " film, rank 0 " +
                        std::to_string(mine.width) + "x" + std::to_string(mine.height));
  // its share of rank 0's samples per pixel (another --spp made a merge with a gap, exit 0)
  if (h.req_begin != expected.begin || h.req_end != expected.end)
    throw lucent::Error("rank " + std::to_string(from) + " is given samples " +
                        lucent::range_text({h.req_begin, h.req_end}) +
                        ", its share of rank 0's is " + lucent::range_text(expected) +
                        " (another --spp?)");
  lucent::PartInfo info = mine;
  info.scene_hash = h.hash;
  info.seed = static_cast<std::uint32_t>(h.seed);
  info.samples.clear();
  if (h.end > h.begin) info.samples.push_back({h.begin, h.end});
  info.requested = {{h.req_begin, h.req_end}};
  info.nonfinite = h.nonfinite;
  info.rays = h.rays;
  info.seconds = h.seconds;
  h.integrator[sizeof h.integrator - 1] = 0;
  info.integrator = h.integrator;
  return info;
}

/// Before rendering: every rank's part header (film, share, seed, integrator, scene hash) agrees
/// with rank 0's, or rank 0 throws naming the first rank that differs. A node with another scene
/// file, --seed, --spp or --precision rendered its whole share, for hours, before rank 0 refused
/// its part (and with --checkpoint again at every rerun).
/// (A rank whose header cannot be made sends an empty one, which rank 0 skips, and then throws:
/// its own line.)
void check_headers(const std::function<lucent::PartInfo()>& header,
                   const std::function<lucent::SampleRange(int)>& share) {
  std::optional<lucent::PartInfo> info;
  std::exception_ptr failure;
  try {
    info = header();
  } catch (...) {
    failure = std::current_exception();
  }
  const Header h = info ? to_header(*info) : Header{};
  std::vector<Header> all(g_rank == 0 ? g_size : 0);
  MPI_Gather(&h, sizeof h, MPI_BYTE, all.data(), sizeof h, MPI_BYTE, 0, MPI_COMM_WORLD);
  if (failure) std::rethrow_exception(failure);
  if (g_rank != 0) return;
  lucent::PartMerger merger;
  merger.add_header("rank 0", *info);
  for (int r = 1; r < g_size; ++r)
    if (all[size_t(r)].width > 0)
      merger.add_header("rank " + std::to_string(r),
                        check_header(all[size_t(r)], r, *info, share(r)));
}

void send_part(const lucent::RenderPart& p) {
  const Header h = to_header(p.info);
  MPI_Send(&h, sizeof h, MPI_BYTE, 0, 0, MPI_COMM_WORLD);
  MPI_Send(p.acc.sum.data(), static_cast<int>(p.acc.sum.size()), MPI_DOUBLE, 0, 1, MPI_COMM_WORLD);
  MPI_Send(p.acc.sumsq.data(), static_cast<int>(p.acc.sumsq.size()), MPI_DOUBLE, 0, 2,
           MPI_COMM_WORLD);
  MPI_Send(p.acc.count.data(), static_cast<int>(p.acc.count.size()), MPI_UINT32_T, 0, 3,
           MPI_COMM_WORLD);
}

/// Rank `from`'s part, its film and share checked (check_headers() checked them before
/// rendering; the merger checks the rest).
lucent::RenderPart receive_part(int from, const lucent::PartInfo& mine,
                                const lucent::SampleRange& expected) {
  Header h{};
  MPI_Recv(&h, sizeof h, MPI_BYTE, from, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  lucent::RenderPart p;
  try {
    p.info = check_header(h, from, mine, expected);
  } catch (const lucent::Error& e) {
    fail(e.what());
  }
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
  lucent::scene_detail::set_warning_sink(on_warning);
  // the scene, the output and the shares, agreed by all ranks: one line, status 1 (a scene no
  // rank could read, the commonest mistake, printed one line per rank and Open MPI's MPI_Abort
  // report)
  lucent::Scene scene;
  std::uint64_t n = 0;
  if (refused([&] {
        if (root) lucent::io::check_output_path(a.output, {a.scene});
        scene = lucent::load_scene(a.scene);
        if (a.width > 0) scene.film.width = a.width;
        if (a.height > 0) scene.film.height = a.height;
        if (a.seed >= 0) scene.integrator.seed = static_cast<std::uint32_t>(a.seed);
        if (a.no_caustics) scene.integrator.caustics = false;
        // nor a file the scene reads (a texture or mesh: rank 0 replaced it)
        if (root)
          lucent::io::check_output_path(a.output,
                                        lucent::scene_detail::scene_inputs(a.scene, scene));
        lucent::check_part_scene(scene, a.scene);
        n = a.spp > 0 ? std::uint64_t(a.spp) : scene.integrator.spp;
        if (n < std::uint64_t(g_size))
          throw lucent::Error(std::to_string(g_size) + " ranks for " + std::to_string(n) +
                              " samples per pixel: use at most one rank per sample");
      }))
    return 1;
  // rank r's share of the samples [0, n)
  auto share = [&](int r) {
    return lucent::SampleRange{n * std::uint64_t(r) / g_size, n * std::uint64_t(r + 1) / g_size};
  };
  const lucent::SampleRange range = share(g_rank);

  // --checkpoint: the arguments, this rank's file (not the output, nor an input) and, on rank 0,
  // no checkpoints of another rank count; then each rank locks and reads its own. Each step is
  // agreed by all ranks: one line, and nothing locked or written when the first refuses.
  std::optional<lucent::cli::Checkpoint> ck;
  const std::string ck_path =
      a.checkpoint.empty() ? "" : rank_checkpoint(a.checkpoint, g_rank, g_size);
  // whether every rank has --checkpoint (mpirun's A : B gives ranks arguments of their own): the
  // ranks with one take collective steps that the others skip, and a job with it on rank 0
  // alone hung in them for ever
  int with_ck = a.checkpoint.empty() ? 0 : 1, all_ck = 0, any_ck = 0;
  MPI_Allreduce(&with_ck, &all_ck, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&with_ck, &any_ck, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (refused([&] {
        if (all_ck != any_ck)
          throw lucent::Error(
              std::string("--checkpoint: rank ") + std::to_string(g_rank) +
              (with_ck ? " has one, another rank has none" : " has none, another rank has one") +
              " (mpirun's A : B): give every rank the same --checkpoint");
        if (a.checkpoint_every > 0 && a.checkpoint.empty())
          throw lucent::Error(
              "--checkpoint-every is how often --checkpoint writes: it does nothing without it");
        if (a.checkpoint.empty()) return;
        if (lucent::io::lower_extension(a.checkpoint) != ".exr")
          throw lucent::Error(a.checkpoint + ": --checkpoint writes part files: use an .exr name");
        // (the name given too, as `lucent render` refuses it: the ranks' files have other names,
        // but the name was the output's, which docs/parts.md says is refused)
        for (const std::string& name : {a.checkpoint, ck_path})
          if (lucent::io::same_file(name, a.output))
            throw lucent::Error(name + ": is the output too: give --checkpoint a name of its own");
        std::vector<std::string> inputs = lucent::scene_detail::scene_inputs(a.scene, scene);
        inputs.push_back(a.scene);
        inputs.push_back(a.output);
        lucent::io::check_output_path(ck_path, inputs, /*is_checkpoint=*/true);
        if (root) refuse_other_rank_counts(a.checkpoint, g_size);
      }))
    return 1;
  // memory beside the session: each rank's part, copied from it before it goes (with a
  // checkpoint: the checkpoint's part and its write, as `lucent render --checkpoint` counts them);
  // then on rank 0 its part, the merge, a part received and the write (refused now rather than
  // after the render), and on the other ranks with a checkpoint their part and its last write
  // (agreed, as the checkpoint's checks: every rank refusing printed a line each; before the
  // checkpoints are locked, so that a refusal leaves no file)
  const int fw = scene.film.width, fh = scene.film.height;
  const std::uint64_t npix = std::uint64_t(fw) * std::uint64_t(fh);
  const std::uint64_t part_bytes = npix * lucent::render_detail::kAccumulationPixelBytes;
  const std::string film = std::to_string(fw) + "x" + std::to_string(fh);
  if (refused([&] {
        if (root) {
          const std::uint64_t write =
              lucent::io::lower_extension(a.output) == ".exr"
                  ? lucent::part_write_bytes(fw, fh)
                  : npix * lucent::render_detail::kResultPixelBytes +
                        lucent::image_detail::image_write_bytes(a.output, fw, fh);
          lucent::render_detail::check_output_host_memory(
              scene,
              {{"rank 0's part, the merged sums and a part received of the " + film + " film",
                3 * part_bytes, "the film size"},
               {"writing " + one_line(a.output) + " (" + film + ")", write, "the film size"}});
        } else if (!a.checkpoint.empty()) {
          lucent::render_detail::check_output_host_memory(
              scene, {{"rank " + std::to_string(g_rank) + "'s part of the " + film + " film",
                       part_bytes, "the film size"},
                      {"writing " + one_line(ck_path) + " (" + film + ")",
                       lucent::part_write_bytes(fw, fh), "the film size"}});
        }
      }))
    return 1;

  if (!a.checkpoint.empty() && refused([&] {
        ck.emplace(
            ck_path, a.scene,
            a.checkpoint_every > 0 ? a.checkpoint_every : lucent::cli::kDefaultCheckpointSeconds,
            "lucent-mpi: rank " + std::to_string(g_rank) + " of " + std::to_string(g_size),
            range.begin);
        ck->read();
      }))
    return 1;

  lucent::SessionOptions so = lucent::SessionOptions::from_environment();
  so.reserved_host_bytes =
      ck ? std::max(part_bytes, lucent::cli::checkpoint_beside_bytes(fw, fh, ck->resumed()))
         : part_bytes;
  if (!a.device.empty()) so.device = a.device;
  so.precision = lucent::parse_precision(a.precision);
  so.fast_math = a.fast_math;
  // the device opened by every rank, agreed: one line naming the lowest rank that cannot (every
  // rank of a job given another machine's --device printed its own, each racing MPI_Abort)
  std::optional<lucent::Renderer> session;
  if (refused([&] { session.emplace(so); })) return 1;
  lucent::Renderer& renderer = *session;
  renderer.set_cancel_flag(&g_stop);
  // agreed as well: a scene the session refuses or a kernel that does not build fails on every
  // rank, which printed one line each and Open MPI's MPI_Abort report
  if (refused([&] {
        try {
          renderer.set_scene(std::move(scene));               // held once, by the session
          lucent::cli::reclaim_stop_handler(on_stop_signal);  // from PoCL's LLVM
        } catch (const lucent::Error&) {
          // a stop signal during the kernel build, where the build failed on it (PoCL's LLVM,
          // when its handlers were in place) or it cancelled a wait for another process's
          // build: the interruption,
          // as `lucent render` reports it, not a build error (it ended the job through
          // MPI_Abort, "kernel build failed", exit 1)
          if (!g_stop.load()) throw;
        }
      }))
    return 1;
  // a rank stopped before rendering ends the job, every rank with 128 + the signal: nothing was
  // rendered, and a rank that went on alone would wait for the others for ever
  if (const int sig = stopped_before_rendering(); sig > 0) return 128 + sig;
  if (refused([&] {
        check_headers([&] { return lucent::part_header(renderer, range, a.scene); }, share);
      }))
    return 1;
  renderer.reset(range.begin);
  // a checkpoint of another image, of other samples (another --spp) or of more than the rank's
  // share: refused before rendering; else the rank starts after its samples
  std::uint64_t todo = range.end - range.begin;
  if (ck && refused([&] { lucent::cli::resume_from(*ck, renderer, todo, /*quiet=*/true); }))
    return 1;
  // said once every rank has accepted its checkpoint: a rank said it resumed, then another rank's
  // refusal ended the job
  if (ck && !a.quiet) lucent::cli::say_resumed(*ck);
  const std::uint64_t resumed = ck ? ck->first_sample() - range.begin : 0;
  const bool tty = isatty(STDERR_FILENO);
  double last = -10;
  // from here until agreement.finish() the ranks' only MPI calls are the agreement's
  StopAgreement agreement(todo > 0, g_mpi_any_thread);
  // the line after a second of rendering; the stop-signal tests' (LUCENT_TEST_EARLY_PROGRESS=1)
  // once every rank has rendered a pass, which a signal to any rank then leaves in its part
  const bool early = lucent::cli::early_progress_for_tests();
  auto progress = [&](const lucent::RenderProgress& p) {
    if (ck) ck->on_pass(renderer);
    // a stop agreed (a signal on another rank): this rank stops after this pass, as for its own
    if (agreement.poll()) renderer.cancel();
    if (!root || a.quiet || (early ? agreement.rounds() < 2 : p.elapsed < 1.0) ||
        (!tty && p.elapsed - last < 2.0))
      return;
    last = p.elapsed;
    // rank 0's share, its checkpoint's samples counted
    const std::uint64_t done = resumed + p.samples_done, all = range.end - range.begin;
    std::fprintf(stderr, "%srank 0 of %d: %5.1f%%  %llu of %llu spp  %.2f Msamples/s%s",
                 tty ? "\r" : "", g_size, 100.0 * double(done) / double(all),
                 static_cast<unsigned long long>(done), static_cast<unsigned long long>(all),
                 p.samples_per_second * 1e-6, tty ? "   " : "\n");
  };
  if (todo > 0) renderer.render(todo, a.time_limit, progress);
  if (root && !a.quiet && last > 0 && tty) std::fprintf(stderr, "\n");
  // every rank's render has ended: its share, its --time, its own stop signal or another rank's
  agreement.finish();
  // with a checkpoint: the render is complete when every rank's is; until then each rank's
  // samples go to its checkpoint, before they are sent (a SIGKILL that follows a SIGTERM during
  // the merge or the output's write loses nothing)
  share_warnings();  // the render's
  // a stop signal on any rank, agreed: the highest signal, and the lowest rank that had one (a
  // rank signalled alone, a node drained, under --time wrote a short image with exit 0 and no
  // word: its missing samples were taken for the time limit's)
  const int my_signal = g_stop.load() ? (g_signal ? int(g_signal) : SIGINT) : 0;
  int stop_signal = 0, stopped_rank = g_size;
  const int my_stop_rank = my_signal ? g_rank : g_size;
  MPI_Allreduce(&my_signal, &stop_signal, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(&my_stop_rank, &stopped_rank, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  // (this rank's stop as agreed above: a signal since then is the next run's)
  int complete = ck ? ck->complete(renderer, my_signal != 0) : 1, all_complete = 1;
  MPI_Allreduce(&complete, &all_complete, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  lucent::RenderPart part = ck ? ck->whole(renderer) : lucent::make_part(renderer, range, a.scene);
  session.reset();  // its sums and device buffers: the part is what is sent, merged and written
  if (ck) {
    ck->drop();
    if (!all_complete && !part.info.samples.empty()) ck->save_new(part);
  }
  // where each rank's checkpoint ends now, for rank 0's last line: a rank whose write failed (a
  // full disk: a warning, the render goes on) holds fewer samples than it sent, and the line said
  // the checkpoints held the output's samples
  std::vector<std::uint64_t> held(root ? g_size : 0);
  auto gather_held = [&] {
    const std::uint64_t mine = ck->held();
    MPI_Gather(&mine, 1, MPI_UINT64_T, held.data(), 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  };
  if (ck) gather_held();
  // every rank's checkpoint goes once rank 0 has written the output of a complete render. When
  // its write failed (a full disk, a directory removed), a complete render's samples go to the
  // checkpoints instead, each rank's whole share (they held those of the last periodic write, up
  // to --checkpoint-every seconds of every rank's work short): the same command then renders
  // nothing and writes the output. (`written` and all_complete are every rank's.)
  auto finish = [&](int written) {
    MPI_Bcast(&written, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (ck && written && all_complete) ck->remove();
    if (ck && !written && all_complete) {
      if (!part.info.samples.empty()) ck->save_new(part);
      gather_held();
    }
  };

  if (!root) {
    send_part(part);
    finish(0);
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
  // what the checkpoints hold, after a stop or a failed write: "lucent-mpi: the checkpoints
  // ck.rank<r>-of-2.exr hold samples [0, 2210), [4000, 6114) of [0, 8000): ..."
  auto say_kept = [&](const std::vector<lucent::SampleRange>& output) {
    std::vector<lucent::SampleRange> kept;  // [B_r, held_r) of each rank, adjacent ones joined
    for (int r = 0; r < g_size; ++r) {
      const lucent::SampleRange s = {share(r).begin, held[r]};
      if (s.end <= s.begin) continue;
      if (!kept.empty() && kept.back().end == s.begin)
        kept.back().end = s.end;
      else
        kept.push_back(s);
    }
    const std::string kept_text =
        kept.empty() ? "no samples" : "samples " + lucent::ranges_text(kept);
    const std::string short_of = kept == output
                                     ? ""
                                     : " (not all of the output's " + lucent::ranges_text(output) +
                                           ": a checkpoint was not written)";
    const bool all = kept == std::vector<lucent::SampleRange>{{0, n}};
    std::fprintf(stderr,
                 "lucent-mpi: the checkpoints %s hold %s of [0, %llu)%s: the same command with %d "
                 "ranks %s\n",
                 one_line(rank_checkpoints(a.checkpoint, g_size)).c_str(), kept_text.c_str(),
                 static_cast<unsigned long long>(n), short_of.c_str(), g_size,
                 all ? "writes the output" : "resumes the render");
  };
  try {
    lucent::write_merged(a.output, m.merged);
  } catch (const lucent::Error& e) {
    if (!ck) throw;
    // one line for the output, then the ranks keep their samples in their checkpoints (rank 0
    // its own part: the merged sums go first, for its write's memory)
    print_failure(e.what());
    const std::vector<lucent::SampleRange> output = m.merged.info.samples;
    m = {};
    finish(0);
    say_kept(output);
    return 1;
  }
  finish(1);
  if (!a.quiet)
    std::fprintf(stderr, "%s: %dx%d, samples %s from %d rank%s (%.2f s of kernel time in all)\n",
                 one_line(a.output).c_str(), m.merged.info.width, m.merged.info.height,
                 lucent::ranges_text(m.merged.info.samples).c_str(), g_size, g_size == 1 ? "" : "s",
                 m.merged.info.seconds);
  if (m.merged.info.nonfinite > 0)
    std::fprintf(
        stderr, "lucent-mpi: warning: %s\n",
        lucent::render_detail::nonfinite_warning(m.merged.info.nonfinite, m.merged.acc.count)
            .c_str());
  if (ck && !all_complete) say_kept(m.merged.info.samples);
  if (stop_signal > 0) {
    const std::string who = stopped_rank == 0
                                ? ""
                                : " (a stop signal on rank " + std::to_string(stopped_rank) +
                                      " of " + std::to_string(g_size) + ")";
    std::fprintf(stderr, "lucent-mpi: interrupted%s: %s holds samples %s of [0, %llu)\n",
                 who.c_str(), one_line(a.output).c_str(),
                 lucent::ranges_text(m.merged.info.samples).c_str(),
                 static_cast<unsigned long long>(n));
    return 128 + stop_signal;
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
  lucent::io::hold_standard_descriptors();  // (`2>&-`: a checkpoint's lock became stderr)
  // before MPI_Init: an MPI singleton's daemon (orted) probes OpenCL devices through hwloc, and
  // PoCL aborts on an empty POCL_CACHE_DIR there, and crashes (SIGSEGV) on a thread count it
  // cannot read (mpirun itself does so before any rank starts)
  for (const std::string& problem : {lucent::cl_util::pocl_empty_cache_dir_problem(),
                                     lucent::cl_util::pocl_thread_count_problem()})
    if (!problem.empty()) {
      std::fprintf(stderr, "lucent-mpi: error: %s\n", problem.c_str());
      return 1;
    }
  // MPI_THREAD_SERIALIZED: a render on several devices calls its progress callback, which polls
  // the ranks' stop agreement (StopAgreement), from the devices' threads, one at a time
  int provided = MPI_THREAD_SINGLE;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
  g_mpi_any_thread = provided >= MPI_THREAD_SERIALIZED;
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  lucent::cli::install_stop_handler(on_stop_signal);

  Args a;
  CLI::App app{
      "lucent-mpi: one render split over MPI ranks (mpirun -np K lucent-mpi SCENE -o OUT)"};
  app.set_version_flag("--version", std::string("lucent-mpi ") + lucent::kVersion);
  app.add_option("scene", a.scene, "Scene file (JSON)")
      ->required()
      ->check(lucent::cli::non_empty());
  app.add_option("-o,--output", a.output, "Output: .exr (a part file), .png or .pfm")
      ->required()
      ->check(lucent::cli::non_empty());
  app.add_option("--spp", a.spp, "Samples per pixel in all (default: the scene's)")
      ->check(CLI::Range(1, lucent::limits::kMaxSpp));
  // as `lucent render --time`: a finite number of seconds up to 1e7 (CLI::PositiveNumber let NaN
  // through to a rank's MPI_Abort, and refused inf naming 1.8e308 in 300 digits)
  const CLI::Validator seconds(
      [](std::string& text) -> std::string {
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v))
          return "must be a finite number of seconds, got " + text;
        return v > 0 && v <= 1e7 ? "" : "must be in (0, 1e7] seconds, got " + text;
      },
      "SECONDS");
  app.add_option("--time", a.time_limit,
                 "Each rank stops after this many seconds (at most 1e7) short of its share of "
                 "--spp or the scene's spp (unlike lucent render --time alone, which renders "
                 "until then: the ranks share a fixed number of samples)")
      ->check(seconds);
  app.add_option("--width", a.width, "Image width")
      ->check(CLI::Range(1, lucent::limits::kMaxImageSize));
  app.add_option("--height", a.height, "Image height")
      ->check(CLI::Range(1, lucent::limits::kMaxImageSize));
  app.add_option("--seed", a.seed, "Random seed")
      ->check(CLI::Range(0LL, static_cast<long long>(lucent::limits::kMaxSeed)));
  app.add_option("--device", a.device, "OpenCL device(s) of every rank (env LUCENT_DEVICE)")
      ->check(lucent::cli::non_empty());
  app.add_option("--precision", a.precision, "float or double")
      ->check(CLI::IsMember({"float", "double"}));
  app.add_flag("--fast-math", a.fast_math, "Build the kernel with -cl-fast-relaxed-math");
  // (a scene with integrator.caustics, scenes/course.json, could not be rendered by ranks
  // without editing it)
  app.add_flag("--no-caustics", a.no_caustics,
               "Caustic paths by the camera path alone (integrator.caustics off: ranks cannot "
               "hold light-traced caustics)");
  app.add_flag("-q,--quiet", a.quiet, "No progress line or summary");
  app.add_option("--checkpoint", a.checkpoint,
                 "Each rank writes the samples it rendered so far to CK.rank<r>-of-<K>.exr every "
                 "--checkpoint-every seconds, and resumes from it when it exists; removed once "
                 "the output is written (docs/parts.md, \"Checkpoints of lucent-mpi\")")
      ->check(lucent::cli::non_empty());
  app.add_option("--checkpoint-every", a.checkpoint_every,
                 "Seconds between two checkpoints (default 300)")
      ->check(seconds);
  // the ranks agree on whether the arguments parse: a rank that ended alone on a parse error
  // (different arguments per rank, mpirun's A : B) left rank 0 waiting for its part for ever
  int failed = 0, parse_status = 0, code = 0;
  std::string message;
  try {
    app.parse(argc, argv);
    // (CLI11 read --spp 010 as octal 8, --time 0x10 as 16)
    if (const std::string bad = lucent::cli::refused_value(app); !bad.empty())
      throw CLI::ValidationError(bad);
  } catch (const CLI::ParseError& e) {
    failed = 1;
    code = e.get_exit_code();
    // an integer that is not plain decimal is named as such (0b11 was "not in range")
    const std::string bad = lucent::cli::refused_value(app);
    const std::string said = bad.empty() ? std::string(e.what()) : bad;
    if (g_rank != 0) {
      // (--help and --version: CLI11's what() is "This should be caught in your main function")
      message = code == 0 ? "--help or --version is for rank 0 alone" : said;
    } else if (code == 0) {
      parse_status = app.exit(e);  // --help, --version: stdout, status 0
    } else {
      // one line and status 2, as `lucent` says it (CLI11's own exit printed two lines and
      // exited 105, 106 or 109)
      std::string what = said;
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
  } catch (const lucent::Error& e) {
    fail(e.what(), e.details());
  } catch (const std::exception& e) {
    fail(e.what());
  }
  MPI_Finalize();
  return status;
}
