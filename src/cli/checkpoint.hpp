#pragma once
// Checkpoints of a render (`lucent render --checkpoint`, `lucent-mpi --checkpoint`; docs/parts.md,
// "Checkpoints"): the samples rendered so far, written every --checkpoint-every seconds as a part
// file, so that a render killed outright (SIGKILL, the OOM killer, a power loss, a crashed driver)
// loses at most that much. A render started with the file present resumes from it. Compiled into
// both programs (cmake/LucentMpi.cmake), which print their own name in its messages.
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "lucent/parts.hpp"
#include "lucent/session.hpp"

namespace lucent::cli {

/// The seconds between two checkpoints without --checkpoint-every.
constexpr double kDefaultCheckpointSeconds = 300;

/// An exclusive lock on `<checkpoint>.lock` for the render's life (flock: a killed render's goes
/// with it): two renders given one checkpoint wrote over each other's samples, and each run's
/// work was lost to the other's next write (the checkpoint review). A checkpoint that is a
/// symbolic link is locked where it leads (`<target>.lock`), as the file its writes replace.
class CheckpointLock {
 public:
  explicit CheckpointLock(const std::string& checkpoint);
  CheckpointLock(const CheckpointLock&) = delete;
  CheckpointLock& operator=(const CheckpointLock&) = delete;
  ~CheckpointLock();
  /// With the checkpoint, once the output is written (while held: a render that opened it
  /// meanwhile locks a file no longer there, as one that finds none creates its own).
  void remove() const;

 private:
  std::string path_;
  int fd_ = -1;
  mutable bool removed_ = false;
};

/// A render's checkpoint: a part file of the samples [B, K) of the render's samples [B, N)
/// (B = 0 for `lucent render`; a rank's first sample for lucent-mpi). A render started with the
/// file present renders the samples [K, N) only, and its image is that of [B, N), the one the
/// render without a stop gives (the same sample indices, summed in another order). The file is
/// removed once the output is written.
class Checkpoint {
 public:
  /// `program`: the messages' prefix ("lucent", "lucent-mpi: rank 1 of 4"). `begin`: B.
  Checkpoint(std::string path, std::string scene_path, double every, std::string program = "lucent",
             std::uint64_t begin = 0);
  Checkpoint(const Checkpoint&) = delete;
  Checkpoint& operator=(const Checkpoint&) = delete;
  /// The lock goes with the checkpoint: a render that ends with no file there (refused, failed
  /// or stopped before its first write) removes the lock it holds (it stayed alone, for ever).
  ~Checkpoint();

  /// Before the session: locks the checkpoint, then reads its header when there is one, so
  /// that a file that is not a part, or one of a corrupt header, is refused before a device is
  /// opened (its pixels: check()).
  void read();
  bool resumed() const { return header_.has_value(); }
  /// K: the sample the checkpoint ends at (B without one), where this render starts.
  std::uint64_t first_sample() const;
  /// B.
  std::uint64_t begin() const { return begin_; }

  /// After set_scene, before rendering: refuses a checkpoint of another image (PartMerger's
  /// checks: film, seed, sampler, integrator, lucent's version, scene hash), one that is not of
  /// the samples [B, K), or one that ends after `target` (N; 0: a time limit alone); then reads
  /// its pixels.
  void check(const lucent::Renderer& renderer, std::uint64_t target);

  /// From on_progress, after each pass: writes the checkpoint when --checkpoint-every seconds
  /// have passed since the last one ended and the session has new samples.
  void on_pass(const lucent::Renderer& renderer);

  /// The samples [B, K + the session's): the checkpoint's and the session's, added.
  lucent::RenderPart whole(const lucent::Renderer& renderer) const;

  /// Writes `part` to the checkpoint, atomically; a failure (a full disk) is a warning: the
  /// render goes on, and the previous checkpoint stays as it was. The warning is said once for
  /// failures in a row that say the same (a full disk with --checkpoint-every 0.05 said it at
  /// every interval), and again after a write that succeeded.
  bool save(const lucent::RenderPart& part);
  /// save(), unless the file holds the part's samples already (written by the last checkpoint,
  /// or read); true when the file holds them after it.
  bool save_new(const lucent::RenderPart& part);

  /// The render asked for is done: N samples (a time limit alone: its time), not stopped.
  bool complete(const lucent::Renderer& renderer, bool stopped) const;
  /// The sample the file ends at ([B, held())): read, or last written; B when there is none.
  std::uint64_t held() const { return held_; }

  /// The checkpoint's part, no longer needed (its samples are in a whole() part).
  void drop() {
    old_.reset();
    header_.reset();
  }

  /// After the output was written: the render is complete, its checkpoint of no further use.
  /// Only a file this render resumed from or wrote: none may be there, or another's (a file
  /// that the output's name reached by another path was removed as the checkpoint).
  void remove() const;

  const std::string& path() const { return path_; }
  const std::string& program() const { return program_; }

 private:
  /// [B, N), or with a time limit alone the samples so far ([B, K + the session's))
  lucent::SampleRange requested(const lucent::Renderer& renderer) const;

  std::string path_, scene_, program_;
  double every_;
  std::uint64_t begin_ = 0;
  std::uint64_t target_ = 0;
  std::optional<lucent::PartInfo> header_;  ///< the checkpoint's header (read())
  std::optional<lucent::RenderPart> old_;   ///< the checkpoint resumed from (check())
  std::chrono::steady_clock::time_point last_;
  std::uint64_t saved_spp_ = 0;  ///< the session's samples per pixel in the last checkpoint
  std::uint64_t held_ = 0;
  bool ours_ = false;   ///< the file at path_ is this render's: resumed from, or written
  std::string failed_;  ///< the last write's failure, said; empty after a write succeeded
  std::optional<CheckpointLock> lock_;
};

/// After a render with a checkpoint, while the session lives: an unfinished render's samples go
/// to the checkpoint, which stays for the next run to resume from; a resumed render's result
/// becomes the image of the checkpoint's samples and the session's (the session is gone then).
/// `stopped`: a stop signal or a cancel ended the render. True when the render is complete; a
/// complete resumed render's part (of all its samples) is then moved to `kept`, for
/// keep_samples_of_failed_output, until the output is written.
bool finish_checkpoint(Checkpoint& ck, std::optional<lucent::Renderer>& renderer,
                       lucent::RenderResult& r, bool stopped,
                       std::optional<lucent::RenderPart>& kept);

/// The output's write failed (a full disk, a directory removed) after a render with a checkpoint:
/// its samples go to the checkpoint unless the file holds them already (a stopped render's,
/// which finish_checkpoint wrote), so that the same command writes the output without rendering
/// them again; a complete render's checkpoint otherwise held only the samples of its last
/// periodic write, up to --checkpoint-every seconds short. The samples: `kept` (a resumed
/// render's, from finish_checkpoint), else the session's while it lives. Then one line says where
/// they are: "lucent: ck.exr holds all the samples, [0, 64): the same command writes the output".
/// `complete`: finish_checkpoint's answer (a stopped render's samples are in the file already).
void keep_samples_of_failed_output(Checkpoint& ck, bool complete,
                                   std::optional<lucent::RenderPart>& kept,
                                   std::optional<lucent::Renderer>& renderer);

/// The line that says what the checkpoint holds after a run that did not end complete, or whose
/// output was not written: "<program>: ck.exr holds samples [0, 27171): the same command resumes
/// the render" (`all`: every sample of the render, "... holds all the samples, [0, 64): the same
/// command writes the output"); "... no checkpoint holds ..." when the file holds none.
void say_kept(const Checkpoint& ck, bool all);

/// Before rendering, with a checkpoint: checks it against the session, starts the session after
/// its samples and makes `spp` (N - B) the samples left; false when none is. Says so (say_resumed)
/// unless `quiet`.
bool resume_from(Checkpoint& ck, lucent::Renderer& renderer, std::uint64_t& spp, bool quiet);

/// "<program>: resuming from <path>, which holds samples [B, K)", when the checkpoint was read.
void say_resumed(const Checkpoint& ck);

/// The host memory a checkpoint needs beside the session, for a width x height film: a
/// checkpoint's part (the session's sums, added to a resumed render's checkpoint, itself held
/// throughout) and the write of its file.
std::uint64_t checkpoint_beside_bytes(int width, int height, bool resumed);

}  // namespace lucent::cli
