#pragma once
// Reading input files with a bound, and writing outputs so that a file under its final name is
// always complete. Every failure throws lucent::Error naming the path.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace lucent::io {

/// What a file being read is, for messages and limits.
struct ReadSpec {
  const char* what = "file";           ///< "scene file", "OBJ file", "texture", ... (for messages)
  std::uint64_t max_bytes = 1u << 30;  ///< larger files (or longer streams) are refused
  /// Pipes (a FIFO, `<(command)`, /dev/stdin) are read up to max_bytes, waiting at most
  /// `stream_idle_seconds` for each chunk; otherwise only regular files are accepted. Devices
  /// and sockets are always refused.
  bool allow_pipe = false;
  int stream_idle_seconds = 10;
  /// Text formats: a NUL byte (a binary file, /dev/zero) stops the read with an error.
  bool text = false;
};

/// The whole content of `path`. Never blocks on a FIFO without a writer, never reads more than
/// spec.max_bytes (+1) bytes, refuses directories and devices. Throws lucent::Error
/// ("<path>: cannot open <what> (<reason>)", "<path>: is a directory, not a <what>", ...).
std::string read_file(const std::string& path, const ReadSpec& spec);

/// Writes `size` bytes to `path` through a temporary file in the same directory that is renamed
/// into place once every byte is written and flushed: a crash, a kill or a full disk never
/// leaves a truncated file under `path` (an existing file stays as it was). A symbolic link is
/// followed (its target is replaced). A file replaced keeps its permissions; being a new file, its
/// other hard links keep the old content. Throws lucent::Error("<path>: cannot write (<reason>)").
void write_file_atomic(const std::string& path, const void* data, std::size_t size);
inline void write_file_atomic(const std::string& path, const std::string& bytes) {
  write_file_atomic(path, bytes.data(), bytes.size());
}

/// The file that write_file_atomic(path) replaces: `path`, or where its chain of symbolic links
/// ends (existing or not). Throws lucent::Error for a loop of links.
std::string write_target_path(const std::string& path);

/// Removes the temporary files that write_file_atomic(path) leaves behind when it is killed in
/// the middle of a write (SIGKILL, the OOM killer, a power loss): the regular files of the names
/// it gives them beside `path`'s target, ".<name>.tmp-<pid>-<n>" (not a directory or a symbolic
/// link of such a name), and no other file, and of those only the ones no process holds
/// (remove_if_unheld: a write in progress holds its temporary file). A name over 128 bytes
/// is left alone (its temporary files carry only its first 128 bytes, which another name may
/// share). Returns how many were removed; failures are ignored.
int remove_stale_temporaries(const std::string& path);

/// For a program's main(), first: the standard descriptors 0, 1 and 2 that the caller closed
/// (`2>&-`) are held open on /dev/null, read-only, so that the program's next open() does not take
/// them (with stderr closed, a checkpoint's lock file was opened as descriptor 2 and the progress
/// lines went into it, over its mark); writes to them still fail (EBADF), as to a closed one.
void hold_standard_descriptors();

/// Writes all `size` bytes to the open descriptor `fd` (retrying short writes and EINTR);
/// throws lucent::Error("<path>: cannot write (<reason>)") on failure. `path` names it.
void write_all(int fd, const void* data, std::size_t size, const std::string& path);

/// Whether the open file `fd` is still the file at `path` (a lock file may be removed, by its
/// owner or `cache clear`, while another process has just opened it or waits on it).
bool is_file_at(int fd, const std::string& path);

/// Removes the regular file `path` (not a symbolic link, a directory or a device node: lstat first,
/// and opening a device can act on it) unless a process holds an flock on it, and returns whether
/// it did. A write's temporary file (write_file_atomic) and a kernel build's lock are held so for
/// their lives: one that no process holds is a killed process's leftover. The lock is taken on
/// the file opened for writing where it can be (NFS emulates flock with fcntl locks, which an
/// exclusive lock needs that for) and the file is unlinked under it, checked to be still the
/// file of that name (another process may have removed it and made a new one meanwhile).
bool remove_if_unheld(const std::string& path);

/// Whether `a` and `b` name the same file: the same file when both exist (symbolic and hard
/// links included), else the same path once made canonical.
bool same_file(const std::string& a, const std::string& b);

/// The extension of `path` with its dot, lower-cased: ".exr", ".png", "" when none.
std::string lower_extension(const std::string& path);

/// What a checkpoint's lock file holds while a render holds the lock (lucent::cli::CheckpointLock).
inline constexpr char kCheckpointLockMark[] = "lucent checkpoint lock\n";

/// Fails early (before rendering) when `out` cannot be written as an image: not a format lucent
/// writes (.png, .pfm, .exr), or check_output_file's reasons.
void check_output_path(const std::string& out, const std::vector<std::string>& inputs,
                       bool is_checkpoint = false);

/// Fails early (before rendering) when the file `out` cannot be written: a directory, a FIFO or
/// a device (or a link to one; check_writable_kind), a directory that does not exist or cannot
/// be written to (tested by creating the temporary file the final write goes through), a name
/// longer than the file system allows, a read-only file, or one of `inputs` ("<out>: is an
/// input of this render (<input>); refusing to overwrite it"). Unless `is_checkpoint` (whose own
/// lock then says so), an output that is the checkpoint of a render in progress is refused too:
/// its `<target>.lock` is held (flock) and begins with kCheckpointLockMark (a lock of that name
/// taken by other means, `flock out.exr.lock lucent ...`, is not a checkpoint's). Opens nothing
/// at `out` itself (a FIFO's open waited for a reader for ever).
void check_output_file(const std::string& out, const std::vector<std::string>& inputs,
                       bool is_checkpoint = false);

/// Throws the error of an output `path` whose extension `ext` (lower-case, with its dot; "" for
/// none) names no format the writer has; `formats` lists them (".png, .pfm or .exr"). A name
/// without one said "unknown output format ''", and the Python writer's said "'.'".
[[noreturn]] void unknown_output_format(const std::string& path, const std::string& ext,
                                        const char* formats);

/// "1.5 GiB", "256.0 MiB", "12.0 KiB", "7 bytes": a size for messages (sys::format_bytes).
std::string format_size(std::uint64_t bytes);

}  // namespace lucent::io
