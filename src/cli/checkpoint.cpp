// Checkpoints (checkpoint.hpp): the lock, the file's life (read, checked, written after a pass,
// removed), and the image of a resumed render.
#include "cli/checkpoint.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <new>
#include <utility>
#include <vector>

#include "cli/stop_signals.hpp"
#include "core/file_io.hpp"
#include "core/text.hpp"
#include "lucent/types.hpp"
#include "render/resources.hpp"

namespace lucent::cli {

using io::one_line;

// beside the file the checkpoint's writes replace: a checkpoint given as a symbolic link and as
// its target is one checkpoint (two locks, one per name, let two renders write it and remove each
// other's write in progress as a stale temporary file)
CheckpointLock::CheckpointLock(const std::string& checkpoint)
    : path_(lucent::io::write_target_path(checkpoint) + ".lock") {
  // a lock file removed by the render that held it (its end, or one that wrote no checkpoint)
  // after this one opened it: locked, it is no longer the file of that name, which a third render
  // may create and lock, and two renders held the checkpoint (the review's find); opened again
  int e = 0;
  for (int attempt = 0;; ++attempt) {
    // not through a symbolic link, and only a file of one name: the lock is truncated and
    // written below, and a link planted in its place (a shared scratch directory) had the render
    // overwrite the file it named
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd_ < 0 && errno == ELOOP)
      throw lucent::Error(path_ +
                          ": the checkpoint's lock is a symbolic link, not a file lucent made "
                          "(remove it)");
    if (fd_ < 0)
      throw lucent::Error(path_ + ": cannot create the checkpoint's lock (" + std::strerror(errno) +
                          ")");
    struct stat st {};
    const bool regular = ::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode);
    if (regular && st.st_nlink == 0 && attempt < 100) {
      // removed by the render that held it since this one opened it: opened again, as below
      ::close(fd_);
      continue;
    }
    if (!regular || st.st_nlink != 1) {
      const bool links = regular && st.st_nlink > 1;
      ::close(fd_);
      fd_ = -1;
      throw lucent::Error(path_ + ": the checkpoint's lock is " +
                          (links
                               ? "a file of " + std::to_string(st.st_nlink) + " names (hard links)"
                               : std::string("not a regular file")) +
                          ", not a file lucent made (remove it)");
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      e = errno;
      break;
    }
    if (attempt == 100) {  // (removed 100 times over while this render opened it)
      ::close(fd_);
      fd_ = -1;
      throw lucent::Error(path_ +
                          ": cannot lock the checkpoint (its lock file keeps being "
                          "removed by another render)");
    }
    if (lucent::io::is_file_at(fd_, path_)) {
      // the mark that tells another command's output check this lock is a checkpoint's
      if (::ftruncate(fd_, 0) == 0) {
        const std::size_t n = sizeof lucent::io::kCheckpointLockMark - 1;
        (void)!::pwrite(fd_, lucent::io::kCheckpointLockMark, n, 0);
      }
      return;
    }
    ::close(fd_);
  }
  ::close(fd_);
  fd_ = -1;
  if (e == EWOULDBLOCK)
    throw lucent::Error(checkpoint + ": another render is using this checkpoint (" + path_ +
                        " is locked): give each render a checkpoint of its own");
  throw lucent::Error(path_ + ": cannot lock the checkpoint (" + std::strerror(e) + ")");
}

CheckpointLock::~CheckpointLock() {
  if (fd_ >= 0) ::close(fd_);
}

void CheckpointLock::remove() const {
  // once: a second unlink could remove the lock of a render that began meanwhile
  if (!removed_) ::unlink(path_.c_str());
  removed_ = true;
}

Checkpoint::Checkpoint(std::string path, std::string scene_path, double every, std::string program,
                       std::uint64_t begin)
    : path_(std::move(path)),
      scene_(std::move(scene_path)),
      program_(std::move(program)),
      every_(every),
      begin_(begin),
      held_(begin) {}

Checkpoint::~Checkpoint() {
  if (!lock_ || ours_) return;
  std::error_code ec;
  if (!std::filesystem::exists(path_, ec) && !ec) lock_->remove();  // (a link's target's)
}

void Checkpoint::read() {
  lock_.emplace(path_);  // first: the file read is no other render's work in progress
  // a checkpoint write killed half-way (SIGKILL, the OOM killer) left its temporary file, as large
  // as the checkpoint, for ever: no other render writes this checkpoint while the lock is held
  lucent::io::remove_stale_temporaries(path_);
  // its header only: its pixels are read once check() has found it of this render (a part of a
  // 1024x1024 film given as a 32x32 render's checkpoint took 315 MB and 2 s before the film's
  // mismatch was said, a forged header of 8192x8192 13 GB and 63 s)
  std::error_code ec;
  if (std::filesystem::exists(path_, ec)) header_ = lucent::read_part_info(path_);
  held_ = first_sample();
  ours_ = header_.has_value();
}

std::uint64_t Checkpoint::first_sample() const {
  return header_ && !header_->samples.empty() ? header_->samples.back().end : begin_;
}

void Checkpoint::check(const lucent::Renderer& renderer, std::uint64_t target) {
  target_ = target;
  last_ = std::chrono::steady_clock::now();
  if (!header_) return;
  const std::vector<lucent::SampleRange>& have = header_->samples;
  if (have.size() > 1 || (have.size() == 1 && have[0].begin != begin_))
    throw lucent::Error(path_ + ": holds samples " + lucent::ranges_text(have) +
                        ", not a checkpoint's [" + std::to_string(begin_) +
                        ", K) (a part of `lucent render --samples`, or a lucent-mpi rank's "
                        "checkpoint: of another rank, or of another --spp, which moves the ranks' "
                        "shares?)");
  lucent::PartMerger merger;  // (the session holds no sample yet: its header, no sums copied)
  merger.add_header(scene_, lucent::part_header(renderer, requested(renderer), scene_));
  merger.check(path_, *header_);
  if (target > 0 && first_sample() > target)
    throw lucent::Error(path_ + ": holds " + std::to_string(first_sample() - begin_) +
                        " samples per pixel, more than the " + std::to_string(target - begin_) +
                        " this render asks for (--spp or the scene's integrator.spp)");
  old_ = lucent::read_render_part(path_);  // (the lock keeps other renders from writing it)
  if (old_->info.samples != header_->samples)
    throw lucent::Error(path_ + ": changed while it was read (its samples were " +
                        lucent::ranges_text(header_->samples) + ", now " +
                        lucent::ranges_text(old_->info.samples) + ")");
}

void Checkpoint::on_pass(const lucent::Renderer& renderer) {
  const double since =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - last_).count();
  if (since < every_ || renderer.spp() == saved_spp_) return;
  std::optional<lucent::RenderPart> part;
  try {
    part = whole(renderer);
  } catch (const lucent::Error&) {
    // several devices: a pass can end before an earlier one, and the samples are not one range
    // until that one has (Renderer::accumulation refuses them): the next pass writes it
    return;
  }
  if (save(*part)) saved_spp_ = renderer.spp();
}

lucent::RenderPart Checkpoint::whole(const lucent::Renderer& renderer) const {
  const lucent::SampleRange asked = requested(renderer);
  lucent::RenderPart part = lucent::make_part(renderer, asked, scene_);
  if (!old_) return part;
  lucent::PartMerger merger;
  merger.add(scene_, std::move(part));  // (moved: the film's sums are not copied)
  merger.add(path_, *old_);
  lucent::RenderPart merged = merger.finish().merged;
  // this run's request, not its union with the checkpoint's: a checkpoint of a run that asked for
  // more (another --spp, or the scene's spp edited) kept that request, and lucent-mpi's rank 0
  // refused the rank's share after it was rendered ("another --spp?"), at every rerun; with one
  // rank the output claimed samples missing from a complete render
  merged.info.requested = {asked};
  return merged;
}

bool Checkpoint::save(const lucent::RenderPart& part) {
  std::string failure;
  try {
    // PIZ: a render pauses for the write (and a stopped job's SIGKILL may follow soon), and reads
    // the file once
    lucent::write_render_part(path_, part, lucent::PartCompression::piz);
  } catch (const lucent::Error& e) {
    failure = one_line(e.what());
  } catch (const std::bad_alloc&) {
    // (the encoder's buffers, under an address-space limit tighter than the count)
    failure = one_line(path_) + ": out of memory";
  }
  const bool ok = failure.empty();
  if (!ok && failure != failed_)
    std::fprintf(stderr, "%s: warning: checkpoint not written: %s\n", program_.c_str(),
                 failure.c_str());
  failed_ = failure;
  if (ok) held_ = part.info.samples.empty() ? begin_ : part.info.samples.back().end;
  ours_ = ours_ || ok;
  last_ = std::chrono::steady_clock::now();
  return ok;
}

bool Checkpoint::save_new(const lucent::RenderPart& part) {
  const std::uint64_t end = part.info.samples.empty() ? begin_ : part.info.samples.back().end;
  return end == held_ || save(part);
}

bool Checkpoint::complete(const lucent::Renderer& renderer, bool stopped) const {
  return !stopped && (target_ == 0 || first_sample() + renderer.spp() >= target_);
}

void Checkpoint::remove() const {
  if (lock_) lock_->remove();
  if (!ours_) return;
  // the file written, where a symbolic link leads (removing the link left the checkpoint, for a
  // later render of its target to resume from); the link stays, and a next run writes through it
  std::error_code ec;
  std::string file = path_;
  try {
    file = lucent::io::write_target_path(path_);
  } catch (const lucent::Error&) {
  }
  if (!std::filesystem::remove(file, ec) && ec)
    std::fprintf(stderr, "%s: warning: %s: checkpoint not removed (%s)\n", program_.c_str(),
                 one_line(path_).c_str(), ec.message().c_str());
}

lucent::SampleRange Checkpoint::requested(const lucent::Renderer& renderer) const {
  // at least to the checkpoint's end: with --time alone (no target) a resumed render's session
  // holds no sample yet when check() makes its part, whose range [0, 0) make_part refuses
  return {begin_, std::max({target_, renderer.first_sample() + renderer.spp(), first_sample()})};
}

bool finish_checkpoint(Checkpoint& ck, std::optional<lucent::Renderer>& renderer,
                       lucent::RenderResult& r, bool stopped,
                       std::optional<lucent::RenderPart>& kept) {
  const bool complete = ck.complete(*renderer, stopped);
  if (complete && !ck.resumed()) return true;  // the session's result is the image
  // stopped before its first sample, with no checkpoint read: nothing to write (with --time alone
  // its part would request no sample, [0, 0), which make_part refuses)
  if (renderer->spp() == 0 && !ck.resumed()) return complete;
  lucent::RenderPart all;
  try {
    all = ck.whole(*renderer);
  } catch (const lucent::Error& e) {
    if (ck.resumed()) throw;  // (the session's samples alone are not the image)
    // (a device's failed pass left a gap: the image is written, the last checkpoint stays)
    std::fprintf(stderr, "%s: warning: checkpoint not written: %s\n", ck.program().c_str(),
                 one_line(e.what()).c_str());
    return false;
  }
  // (stopped before its first sample: nothing to write; right after a periodic checkpoint, or
  // before a resumed run's first pass: the file holds these samples already, and writing them
  // again took seconds in which a second Ctrl-C lost the output)
  if (!complete && !all.info.samples.empty()) ck.save_new(all);
  if (!ck.resumed()) return complete;
  // the session's sums and images, and the checkpoint's, before the image's own memory
  renderer.reset();
  ck.drop();
  r.mean = {};
  r.variance = {};
  r.samples = {};
  lucent::RenderResult m = lucent::part_result(all);
  // a complete render's samples, for the checkpoint should the output's write fail (the memory
  // counted after the session holds them: "the sums of the checkpoint and this render")
  if (complete) kept = std::move(all);
  all = {};
  r.mean = std::move(m.mean);
  r.variance = std::move(m.variance);
  r.samples = std::move(m.samples);
  r.spp = m.spp;  // (the render's totals: the checkpoint's samples too)
  r.nonfinite = m.nonfinite;
  r.rays = m.rays;
  r.seconds = m.seconds;
  return complete;
}

void keep_samples_of_failed_output(Checkpoint& ck, bool complete,
                                   std::optional<lucent::RenderPart>& kept,
                                   std::optional<lucent::Renderer>& renderer) {
  if (complete && !kept && renderer) {
    try {
      kept = ck.whole(*renderer);
    } catch (const lucent::Error& e) {
      std::fprintf(stderr, "%s: warning: checkpoint not written: %s\n", ck.program().c_str(),
                   one_line(e.what()).c_str());
    }
  }
  renderer.reset();  // (its sums are in the part: its memory, before the write's)
  const bool all = complete && kept && ck.save_new(*kept);
  kept.reset();
  say_kept(ck, all);
}

void say_kept(const Checkpoint& ck, bool all) {
  const unsigned long long begin = ck.begin(), held = ck.held();
  std::error_code ec;
  if (held == begin)
    std::fprintf(stderr,
                 "%s: no checkpoint holds the samples (%s not written): the same command "
                 "renders them again\n",
                 ck.program().c_str(), one_line(ck.path()).c_str());
  else if (!std::filesystem::exists(ck.path(), ec) && !ec)
    // removed since its last write (its directory too, and the writes since failed): it said
    // the file that was gone held the samples
    std::fprintf(stderr,
                 "%s: no checkpoint holds the samples (%s, written with samples [%llu, %llu), "
                 "no longer exists): the same command renders them again\n",
                 ck.program().c_str(), one_line(ck.path()).c_str(), begin, held);
  else if (all)
    std::fprintf(stderr,
                 "%s: %s holds all the samples, [%llu, %llu): the same command writes the "
                 "output\n",
                 ck.program().c_str(), one_line(ck.path()).c_str(), begin, held);
  else
    std::fprintf(stderr, "%s: %s holds samples [%llu, %llu): the same command resumes the render\n",
                 ck.program().c_str(), one_line(ck.path()).c_str(), begin, held);
}

void say_resumed(const Checkpoint& ck) {
  if (!ck.resumed()) return;
  std::fprintf(stderr, "%s: resuming from %s, which holds samples [%llu, %llu)\n",
               ck.program().c_str(), one_line(ck.path()).c_str(),
               static_cast<unsigned long long>(ck.begin()),
               static_cast<unsigned long long>(ck.first_sample()));
}

bool resume_from(Checkpoint& ck, lucent::Renderer& renderer, std::uint64_t& spp, bool quiet) {
  const std::uint64_t begin = ck.begin();
  ck.check(renderer, spp == 0 ? 0 : begin + spp);
  const std::uint64_t first = ck.first_sample();
  renderer.reset(first);  // (as --samples first:N does)
  if (!quiet) say_resumed(ck);
  if (spp == 0) return true;  // a time limit alone: as long again
  spp = begin + spp - first;
  return spp > 0;
}

std::uint64_t checkpoint_beside_bytes(int width, int height, bool resumed) {
  const std::uint64_t acc_bytes =
      std::uint64_t(width) * std::uint64_t(height) * lucent::render_detail::kAccumulationPixelBytes;
  return (resumed ? 2 : 1) * acc_bytes +
         lucent::part_write_bytes(width, height, lucent::PartCompression::piz);
}

}  // namespace lucent::cli
