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

/// Builds `source` with `options`, through the cache in `cache_dir` ("": no cache).
cl::Program build_program_cached(const Context& ctx, const std::string& source,
                                 const std::string& options, const std::string& cache_dir,
                                 ProgramBuildInfo* info = nullptr);

/// Removes every cache entry of `dir`; returns how many files were removed.
int clear_program_cache(const std::string& dir);

}  // namespace lucent::cl_util
