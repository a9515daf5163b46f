#include "cl/program_cache.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include "core/file_io.hpp"
#include "core/text.hpp"
#include "lucent/error.hpp"
#include "lucent/version.hpp"
#include "scene/loaders.hpp"

namespace lucent::cl_util {

namespace fs = std::filesystem;

namespace {

const char kMagic[] = "LUCENT-PROGRAM-CACHE-1\n";

std::uint64_t fnv1a(const void* data, size_t n, std::uint64_t h = 1469598103934665603ull) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

std::string hex(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

std::string cache_key(const Context& ctx, const std::string& source, const std::string& options) {
  std::ostringstream k;
  k << "lucent " << kVersion << "\nplatform " << ctx.device.info.platform << " "
    << ctx.device.platform.getInfo<CL_PLATFORM_VERSION>() << "\ndevice " << ctx.device.info.name
    << " (" << ctx.device.info.vendor << ")\ndriver " << ctx.device.info.driver_version
    << "\noptions " << options << "\nsource " << hex(fnv1a(source.data(), source.size())) << " "
    << source.size() << "\n";
  return k.str();
}

// An entry: magic, key length, key, binary length, checksum, binary. Read with a bound and from
// regular files only (an entry replaced by a FIFO or a device must not hang or flood a build).
bool read_entry(const std::string& path, const std::string& key, std::vector<unsigned char>& binary,
                std::string& why) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(path, ec))) return false;  // a miss, not an error
  std::string bytes;
  try {
    io::ReadSpec spec;
    spec.what = "cache entry";
    spec.max_bytes = (1ull << 31) + (2u << 20);
    bytes = io::read_file(path, spec);
  } catch (const Error& e) {
    // removed since the look above (an eviction by another process): a miss too; it was
    // reported as a damaged entry (ProgramCacheLock.EvictionsRacingLoadsCostRebuilds, 1 run
    // in a few dozen)
    if (!fs::exists(fs::symlink_status(path, ec))) return false;
    why = e.what();
    return false;
  }
  const size_t magic_len = sizeof kMagic - 1;
  std::uint64_t key_len = 0, bin_len = 0, checksum = 0;
  size_t at = magic_len + sizeof key_len;
  if (bytes.size() < at || bytes.compare(0, magic_len, kMagic) != 0) {
    why = "bad header";
    return false;
  }
  std::memcpy(&key_len, bytes.data() + magic_len, sizeof key_len);
  if (key_len > (1u << 20) || bytes.size() - at < key_len + 2 * sizeof(std::uint64_t)) {
    why = "bad header";
    return false;
  }
  if (bytes.compare(at, key_len, key) != 0 || key_len != key.size()) {
    why = "stale or colliding key";
    return false;
  }
  at += key_len;
  std::memcpy(&bin_len, bytes.data() + at, sizeof bin_len);
  std::memcpy(&checksum, bytes.data() + at + sizeof bin_len, sizeof checksum);
  at += 2 * sizeof(std::uint64_t);
  if (bin_len == 0 || bin_len > (1ull << 31)) {
    why = "bad binary size";
    return false;
  }
  if (bytes.size() - at != bin_len) {
    why = "truncated or oversized entry";
    return false;
  }
  binary.assign(bytes.begin() + static_cast<std::ptrdiff_t>(at), bytes.end());
  if (fnv1a(binary.data(), binary.size()) != checksum) {
    why = "checksum mismatch";
    return false;
  }
  return true;
}

// Warns once per process and message: a cache that cannot be used only costs speed.
void warn_once(const std::string& message) {
  static std::mutex mutex;
  static std::set<std::string> said;
  std::lock_guard<std::mutex> lock(mutex);
  if (said.insert(message).second) scene_detail::warn(message);
}

bool write_entry(const std::string& path, const std::string& key,
                 const std::vector<unsigned char>& binary) {
  std::uint64_t key_len = key.size(), bin_len = binary.size();
  std::uint64_t checksum = fnv1a(binary.data(), binary.size());
  std::string bytes(kMagic, sizeof kMagic - 1);
  bytes.append(reinterpret_cast<const char*>(&key_len), sizeof key_len);
  bytes += key;
  bytes.append(reinterpret_cast<const char*>(&bin_len), sizeof bin_len);
  bytes.append(reinterpret_cast<const char*>(&checksum), sizeof checksum);
  bytes.append(reinterpret_cast<const char*>(binary.data()), binary.size());
  try {
    io::write_file_atomic(path, bytes);  // readers never see a half-written entry
    return true;
  } catch (const Error& e) {
    warn_once(std::string(e.what()) +
              "; the kernel cache is not updated (kernels are built "
              "again next time)");
    return false;
  }
}

}  // namespace

/// An exclusive flock on `path` held while alive: processes that miss the same entry at the same
/// time build it once (the others wait, then read what the first wrote) instead of each compiling
/// it. Waits at most `max_wait` seconds (a holder stuck in a driver must not stall every other
/// process), then builds without the lock, or until `stop` returns true (the render was
/// cancelled: stopped(), and build_program_cached builds nothing); any failure to lock only costs a
/// redundant build. A lock file removed while this process opened it or waited on it is opened
/// again: two builders locking two files of one name would both build.
class BuildLock {
 public:
  BuildLock(const std::string& path, double max_wait, const std::function<bool()>& stop) {
    std::error_code ec;
    fs::create_directories(fs::path(path).parent_path(), ec);
    auto t0 = std::chrono::steady_clock::now();
    auto give_up = [&] {
      if (stop && stop()) return stopped_ = true;
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >
             max_wait;
    };
    for (;;) {
      // (not through a symbolic link: it would create the file a dangling one names)
      fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
      if (fd_ < 0) return;
      while (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        if (errno != EWOULDBLOCK || give_up()) {
          ::close(fd_);
          fd_ = -1;
          return;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      if (io::is_file_at(fd_, path)) return;
      ::close(fd_);
      fd_ = -1;
      if (give_up()) return;
    }
  }
  ~BuildLock() {
    if (fd_ >= 0) ::close(fd_);  // releases the lock
  }
  BuildLock(const BuildLock&) = delete;
  BuildLock& operator=(const BuildLock&) = delete;
  /// The wait ended on `stop` (the caller then builds nothing: build_program_cached throws).
  bool stopped() const { return stopped_; }

 private:
  int fd_ = -1;
  bool stopped_ = false;
};

namespace {
/// A wait for another process's build that `stop` ended: the build is the caller's to skip
/// (it built the kernel anyway, seconds to minutes, and a Ctrl-C in Python came after it).
void throw_if_stopped(const BuildLock& lock, const std::string& path) {
  if (lock.stopped())
    throw Error(
        "kernel build cancelled while it waited for another process's build of the same "
        "kernel (" +
        path + ")");
}
}  // namespace

std::string default_program_cache_dir() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg && *xdg) return std::string(xdg) + "/lucent";
  const char* home = std::getenv("HOME");
  if (home && *home) return std::string(home) + "/.cache/lucent";
  return "";
}

namespace {

// The cache directory if it can be used: a directory that exists or can be made and that this
// process can write; otherwise "" after one warning (a cache that cannot be used only costs
// speed).
std::string usable_cache_dir(const std::string& dir) {
  if (dir.empty()) return dir;
  const std::string origin = "kernel cache";
  std::error_code ec;
  fs::file_status st = fs::status(dir, ec);
  std::string why;
  if (fs::exists(st)) {
    if (!fs::is_directory(st))
      why = "not a directory";
    else if (::access(dir.c_str(), W_OK | X_OK) != 0)
      why = std::strerror(errno);
  } else if (!fs::create_directories(dir, ec) && ec) {
    why = ec.message();
  }
  if (!why.empty()) {
    warn_once(origin + " " + dir + ": " + why + "; kernels are built without the cache");
    return "";
  }
  return dir;
}

}  // namespace

std::string driver_program_cache(const Device& device) {
  if (!is_pocl(device.info)) return "";
  // PoCL reads the variable as on when it is unset or starts with "1" (pocl_get_bool_option)
  const char* v = std::getenv("POCL_KERNEL_CACHE");
  if (v && v[0] != '1') return "";
  return "PoCL's kernel cache";
}

bool keeps_program_binaries(const Device& device) { return !is_pocl(device.info); }

DeferredEntry::DeferredEntry() = default;
DeferredEntry::~DeferredEntry() = default;
DeferredEntry::DeferredEntry(DeferredEntry&&) noexcept = default;
DeferredEntry& DeferredEntry::operator=(DeferredEntry&&) noexcept = default;

void DeferredEntry::store(const cl::Program& program) {
  if (!file_.empty()) {
    try {
      auto bins = program.getInfo<CL_PROGRAM_BINARIES>();
      if (bins.size() == 1 && !bins[0].empty() && write_entry(file_, key_, bins[0]))
        evict_program_cache(fs::path(file_).parent_path().string(), program_cache_max_bytes(),
                            file_);
    } catch (const cl::Error&) {
      // some drivers cannot return binaries: no cache, no harm
    }
  }
  file_.clear();
  key_.clear();
  lock_.reset();
}

cl::Program build_program_cached(const Context& ctx, const std::string& source,
                                 const std::string& options, const std::string& cache_dir,
                                 ProgramBuildInfo* info, DeferredEntry* deferred, bool entries,
                                 const std::function<bool()>& stop) {
  auto t0 = std::chrono::steady_clock::now();
  ProgramBuildInfo local;
  ProgramBuildInfo& bi = info ? *info : local;
  bi = ProgramBuildInfo{};
  // without entries the directory holds locks only: one that cannot serve goes unsaid (BuildLock
  // fails quietly)
  const std::string dir = entries ? usable_cache_dir(cache_dir) : cache_dir;
  std::string key = cache_key(ctx, source, options);
  auto finish = [&](cl::Program p) {
    bi.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return p;
  };
  DeferredEntry entry;
  if (!dir.empty() && !entries) {
    const std::string file = dir + "/" + hex(fnv1a(key.data(), key.size())) + ".bin";
    entry.lock_ = std::make_unique<BuildLock>(file + ".lock", 600, stop);
    throw_if_stopped(*entry.lock_, file + ".lock");
  } else if (!dir.empty()) {
    bi.cache_file = dir + "/" + hex(fnv1a(key.data(), key.size())) + ".bin";
    std::string why;
    auto load = [&](cl::Program& p) {
      std::vector<unsigned char> binary;
      why.clear();
      if (!read_entry(bi.cache_file, key, binary, why)) return false;
      try {
        cl::Program::Binaries bins{binary};
        p = cl::Program(ctx.context, {ctx.device.device}, bins);
        p.build({ctx.device.device}, options.c_str());
        bi.cache_hit = true;
        // a use: the entry's mtime orders evictions (fails harmlessly once it is removed)
        ::utimensat(AT_FDCWD, bi.cache_file.c_str(), nullptr, 0);
        return true;
      } catch (const cl::Error&) {
        why = "the driver rejected the binary";
        return false;
      }
    };
    cl::Program p;
    if (load(p)) return finish(p);
    // a miss: wait for another process that may be building this entry, then look again
    entry.lock_ = std::make_unique<BuildLock>(bi.cache_file + ".lock", 600, stop);
    throw_if_stopped(*entry.lock_, bi.cache_file + ".lock");
    if (load(p)) return finish(p);
    if (!why.empty()) {
      bi.note = (why.rfind(bi.cache_file, 0) == 0 ? why : bi.cache_file + ": " + why) + "; rebuilt";
      std::error_code ec;
      fs::remove(bi.cache_file, ec);
    }
    entry.file_ = bi.cache_file;
    entry.key_ = key;
  }
  cl::Program p = build_program(ctx, source, options);
  if (deferred)
    *deferred = std::move(entry);
  else
    entry.store(p);
  return finish(p);
}

namespace {

/// A file the cache writes: "<16 hex digits>.bin", its ".lock", or a write's hidden temporary
/// (".<16 hex digits>.bin.tmp-<pid>-<n>"). Nothing else in the directory is the cache's to
/// delete: a cache directory given by mistake (".", a home directory) lost every *.bin file in it,
/// and a user's file named "<16 hex digits>.bin.old.bin" was counted and removed as an entry.
bool cache_file_name(const std::string& name) {
  const size_t at = !name.empty() && name[0] == '.' ? 1 : 0;  // a temporary's dot
  if (name.size() < at + 20 || name.compare(at + 16, 4, ".bin") != 0 ||
      !std::all_of(name.begin() + at, name.begin() + at + 16,
                   [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); }))
    return false;
  const std::string tail = name.substr(at + 20);
  if (at == 0) return tail.empty() || tail == ".lock";
  return tail.compare(0, 5, ".tmp-") == 0 && tail.size() > 5 &&
         tail.find_first_not_of("0123456789-", 5) == std::string::npos;
}

// The files of the cache directory `dir` that the cache wrote (none when `dir` does not exist).
// A file, or a directory that cannot be listed, is an error (it said "removed 0" for
// LUCENT_CACHE_DIR=/etc/passwd).
std::vector<fs::directory_entry> cache_files(const std::string& dir) {
  std::vector<fs::directory_entry> files;
  std::error_code ec;
  if (dir.empty()) return files;
  if (!fs::exists(dir, ec) && !ec) {
    // a cache not made yet is empty, unless it cannot be made: a path below a file said "removed
    // 0 cached program(s)" and "programs: 0", where the one naming the file was an error
    for (fs::path p = fs::path(dir).parent_path(); !p.empty() && p != p.parent_path();
         p = p.parent_path())
      if (fs::exists(p, ec)) {
        if (!fs::is_directory(p, ec))
          throw Error(dir + ": cannot be the kernel cache (LUCENT_CACHE_DIR): " + p.string() +
                      " is not a directory");
        break;
      }
    return files;
  }
  // (a path that cannot be looked at was "not a directory": permission denied, a name too long)
  if (ec) throw Error(dir + ": cannot look at the kernel cache (" + ec.message() + ")");
  if (!fs::is_directory(dir, ec))
    throw Error(dir + ": not a directory (the kernel cache, LUCENT_CACHE_DIR)");
  fs::directory_iterator it(dir, ec);
  if (ec) throw Error(dir + ": cannot list the kernel cache (" + ec.message() + ")");
  for (; it != fs::directory_iterator(); it.increment(ec))
    if (cache_file_name(it->path().filename().string())) files.push_back(*it);
  return files;
}

// An entry, "<key>.bin" (not a lock, not a write's temporary), as a file of its own: a directory
// or a symbolic link of such a name is not one the cache wrote (info counted a link, and its
// target's size, that clear left alone).
bool is_entry(const fs::directory_entry& e) {
  std::error_code ec, link_ec;
  return e.path().extension() == ".bin" && e.path().filename().string()[0] != '.' &&
         e.is_regular_file(ec) && !e.is_symlink(link_ec);
}

// Removes the lock file `path` unless a process holds it (one that opened it and waits for it
// sees that it is gone: BuildLock).
void remove_unused_lock(const std::string& path) { io::remove_if_unheld(path); }

}  // namespace

std::uint64_t program_cache_max_bytes() {
  const double fallback_mb = 256;
  const char* v = std::getenv("LUCENT_CACHE_MAX_MB");
  if (!v || !*v) return static_cast<std::uint64_t>(fallback_mb) << 20;
  // plain decimal, as the command line's numbers (strtod took "0x10" and " 16"), in the "C"
  // locale (a Python program's German locale read "0.5" as 0: no limit); a value that underflows
  // (1e-400) is a tiny limit, not none
  io::CNumbers c_numbers;
  errno = 0;
  double mb = io::plain_decimal_real(v) ? std::strtod(v, nullptr) : -1;
  if (mb == 0 && errno == ERANGE) mb = std::signbit(mb) ? -1 : 1e-300;  // (-1e-400: refused)
  if (!std::isfinite(mb) || mb < 0) {
    warn_once(
        std::string("LUCENT_CACHE_MAX_MB='") + v +
        "' is not a size in MiB (a decimal number, 0 for no limit); the kernel cache keeps its "
        "default limit of 256 MiB");
    mb = fallback_mb;
  }
  if (mb == 0) return 0;
  // at least one byte (a tiny limit is not "no limit"), and no overflow
  return static_cast<std::uint64_t>(std::clamp(mb * 1048576.0, 1.0, 1e18));
}

ProgramCacheUsage program_cache_usage(const std::string& dir) {
  ProgramCacheUsage usage;
  for (const fs::directory_entry& e : cache_files(dir)) {
    std::error_code ec;
    if (!is_entry(e)) continue;
    const std::uintmax_t bytes = e.file_size(ec);
    if (ec) continue;  // removed meanwhile
    ++usage.programs;
    usage.bytes += bytes;
  }
  return usage;
}

int evict_program_cache(const std::string& dir, std::uint64_t max_bytes, const std::string& keep) {
  if (max_bytes == 0) return 0;
  std::vector<fs::directory_entry> files;
  try {
    files = cache_files(dir);
  } catch (const Error&) {
    return 0;  // a cache that cannot be listed stays as it is: it only costs disk
  }
  struct Entry {
    fs::file_time_type used;
    std::uint64_t bytes;
    fs::path path;
  };
  std::vector<Entry> entries;
  std::uint64_t total = 0;
  for (const fs::directory_entry& e : files) {
    std::error_code time_ec, size_ec;
    if (!is_entry(e)) continue;
    Entry entry{e.last_write_time(time_ec), e.file_size(size_ec), e.path()};
    if (time_ec || size_ec) continue;  // removed meanwhile
    total += entry.bytes;
    entries.push_back(entry);
  }
  if (total <= max_bytes) return 0;
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return a.used < b.used; });
  const fs::path kept = fs::path(keep).filename();
  int removed = 0;
  for (const Entry& e : entries) {
    if (total <= max_bytes) break;
    if (e.path.filename() == kept) continue;
    std::error_code ec;
    if (fs::remove(e.path, ec)) ++removed;
    total -= e.bytes;  // gone either way (another process may have removed it first)
  }
  // then the build locks of entries that are gone, evicted or not (one held is a build underway)
  for (const fs::directory_entry& e : files) {
    const std::string lock = e.path().string();
    std::error_code ec;
    if (e.path().extension() == ".lock" &&
        !fs::exists(lock.substr(0, lock.size() - std::strlen(".lock")), ec) && !ec)
      remove_unused_lock(lock);
  }
  return removed;
}

namespace {
/// Whether the temporary file `name` (".<key>.bin.tmp-<pid>-<n>") is a write in progress: its
/// process is alive. `cache clear` removed those too, and the writer then warned "<key>.bin:
/// cannot write (No such file or directory)".
bool write_in_progress(const std::string& name) {
  const size_t at = name.rfind(".tmp-");
  if (at == std::string::npos) return false;
  const std::string tail = name.substr(at + 5);
  const size_t dash = tail.find('-');
  if (dash == 0 || dash == std::string::npos || dash > 9) return false;
  const long pid = std::strtol(tail.substr(0, dash).c_str(), nullptr, 10);
  return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
}
}  // namespace

int clear_program_cache(const std::string& dir) {
  int n = 0;
  std::string failed;  // the first entry not removed, and why (it said "removed 0", status 0)
  int not_removed = 0;
  for (const fs::directory_entry& e : cache_files(dir)) {
    const std::string name = e.path().filename().string();
    std::error_code ec;
    // only files the cache writes: a directory or a link of such a name is not one (a directory
    // "0000000000000000.bin" was removed and counted as a program, which info did not count)
    if (!e.is_regular_file(ec) || e.is_symlink(ec)) continue;
    if (e.path().extension() == ".lock") {
      remove_unused_lock(e.path().string());  // build locks: not entries, not counted; one held
      continue;                               // is a build underway (as eviction leaves it)
    }
    // entries, counted as info counts them, and the temporary files of interrupted writes
    if (is_entry(e)) {
      if (fs::remove(e.path(), ec)) {
        ++n;
      } else if (ec) {
        if (not_removed++ == 0) failed = e.path().string() + ": " + ec.message();
      }
    } else if (name.find(".bin.tmp") != std::string::npos && !write_in_progress(name)) {
      fs::remove(e.path(), ec);  // an interrupted write's
    }
  }
  if (not_removed > 0)
    throw Error("cannot remove " + std::to_string(not_removed) + " cached program(s) (" + failed +
                "); removed " + std::to_string(n));
  return n;
}

}  // namespace lucent::cl_util
