#pragma once
// On-disk cache of built OpenCL program binaries.
//
// Key: lucent version, platform and device names, driver version, build options and the full
// kernel source; the file name is a 64-bit hash of the key and the file repeats the key, so a
// hash collision, a truncated or corrupt file, or a stale entry (another driver or lucent
// version) is detected and rebuilt. The directory is the caller's (SessionOptions::cache_dir;
// the CLI's default is LUCENT_CACHE_DIR, "off" disabling it); "" disables the cache.
// A miss is built under an exclusive lock on <entry>.lock, so that processes missing the same
// entry at once (a parallel test run on cold caches) compile it once and the others read it.
// The cache is bounded: after writing an entry it removes the least recently used others (a load
// renews an entry's mtime) while the entries hold more than LUCENT_CACHE_MAX_MB
// (program_cache_max_bytes), with their build locks when no process holds them. A removal racing
// a load costs a rebuild: a reader that opened the entry reads it whole, one that comes later
// misses it, and a lock file removed under a waiting builder is noticed (BuildLock).
//
// Drivers that cache their own builds: PoCL keeps every program it builds and every work-group
// function it compiles at a launch (POCL_CACHE_DIR, while POCL_KERNEL_CACHE is on, its default),
// and rebuilds the megakernel from its cache in 0.03 s; answering CL_PROGRAM_BINARIES costs it a
// work-group compile of its own (0.5 s, the largest part of a cold build). The session therefore
// leaves caching to such a driver (driver_program_cache) and stores an entry only for the others,
// after the first launch (DeferredEntry), so that the entry also holds what the driver compiled
// there: a hit then launches at once instead of compiling again. On PoCL with its cache off the
// session stores no entry either (keeps_program_binaries).
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "cl/context.hpp"

namespace lucent::cl_util {

struct ProgramBuildInfo {
  bool cache_hit = false;
  double seconds = 0;
  std::string cache_file;  ///< "" when the cache is disabled
  std::string note;        ///< why an entry was rejected, if one was
};

/// The default cache directory: $XDG_CACHE_HOME/lucent, else ~/.cache/lucent ("" when neither
/// variable is set).
std::string default_program_cache_dir();

/// What caches the driver of `device` keeps of the programs it builds, when lucent's cache would
/// add nothing to them: "PoCL's kernel cache" on PoCL unless POCL_KERNEL_CACHE is set to a value
/// that PoCL reads as off (one not starting with 1); "" otherwise.
std::string driver_program_cache(const Device& device);

/// Whether a session keeps the programs it builds for `device` in lucent's cache: not on PoCL.
/// With its kernel cache on, PoCL's own serves (above). With it off, PoCL (3.1) unpacks a program
/// made from a binary into a directory named after the binary (POCL_CACHE_DIR/_UNCACHED_...)
/// and removes that directory when the program is released: two processes that loaded one entry
/// shared it, and one aborted when the other's release removed it ("Can't get stat() on ...":
/// lucent-mpi's ranks, 2 jobs of 3; two renders, 1 pair in 60). A program built from source gets
/// a directory of its own.
bool keeps_program_binaries(const Device& device);

class BuildLock;

/// A cache miss whose entry is written later, by store(), holding the miss's build lock until then
/// (processes that miss the same entry still build it once). Writes nothing if dropped unstored.
class DeferredEntry {
 public:
  DeferredEntry();
  ~DeferredEntry();
  DeferredEntry(DeferredEntry&&) noexcept;
  DeferredEntry& operator=(DeferredEntry&&) noexcept;

  /// An entry to write or a lock to release.
  bool pending() const { return !file_.empty() || lock_; }
  /// Writes the program's binaries, if an entry is due (a driver that cannot give them: no
  /// entry, no error), and releases the lock.
  void store(const cl::Program& program);

 private:
  friend cl::Program build_program_cached(const Context&, const std::string&, const std::string&,
                                          const std::string&, ProgramBuildInfo*, DeferredEntry*,
                                          bool, const std::function<bool()>&);
  std::string file_, key_;
  std::unique_ptr<BuildLock> lock_;
};

/// Builds `source` with `options`, through the cache in `cache_dir` ("": no cache). A miss is
/// stored at once, or, with `deferred`, when the caller calls deferred->store() (after a launch).
/// With `entries` false (a driver that caches its own builds) no entry is read or written, but
/// the build still takes the entry's lock (held by `deferred` until store()), so that processes
/// building the same program at once wait for the first and then build from the driver's cache.
/// The wait for another process's lock (at most 600 s) ends early once `stop` returns true (a
/// cancelled render: a stopped or stuck holder kept an interrupted render waiting for the whole
/// 600 s), and the build is then cancelled: lucent::Error "kernel build cancelled while it waited
/// ..." (until 30 Nov 2026 it built without the lock, which kept a Ctrl-C waiting for a build).
cl::Program build_program_cached(const Context& ctx, const std::string& source,
                                 const std::string& options, const std::string& cache_dir,
                                 ProgramBuildInfo* info = nullptr,
                                 DeferredEntry* deferred = nullptr, bool entries = true,
                                 const std::function<bool()>& stop = nullptr);

/// The cache's size limit in bytes, from LUCENT_CACHE_MAX_MB (MiB, a fraction allowed): 256 MiB
/// when unset or empty, 0 (no limit) for "0"; any other value that is not a number of 0 or more
/// warns once and keeps the default.
std::uint64_t program_cache_max_bytes();

struct ProgramCacheUsage {
  int programs = 0;         ///< entries ("<key>.bin")
  std::uint64_t bytes = 0;  ///< their total size
};

/// What the entries of `dir` hold (nothing when `dir` does not exist). Throws lucent::Error when
/// `dir` is not a directory or cannot be listed.
ProgramCacheUsage program_cache_usage(const std::string& dir);

/// While the entries of `dir` hold more than `max_bytes` (0: no limit), removes the least
/// recently used (oldest mtime) but `keep` (a path, "" for none), and then the build locks of
/// entries that are gone, each one only when no process holds it. Only files the cache writes are
/// touched; failures are ignored. Returns the number of entries removed.
int evict_program_cache(const std::string& dir, std::uint64_t max_bytes,
                        const std::string& keep = "");

/// Removes every cache entry of `dir`; returns how many files were removed (0 when `dir` does not
/// exist). Throws lucent::Error when `dir` is not a directory or cannot be listed.
int clear_program_cache(const std::string& dir);

}  // namespace lucent::cl_util
