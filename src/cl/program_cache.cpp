#include "cl/program_cache.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>
#include <vector>

#include "lucent/error.hpp"
#include "lucent/version.hpp"

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

bool read_entry(const std::string& path, const std::string& key, std::vector<unsigned char>& binary,
                std::string& why) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return false;  // a miss, not an error
  std::string magic(sizeof kMagic - 1, '\0');
  f.read(&magic[0], static_cast<std::streamsize>(magic.size()));
  std::uint64_t key_len = 0, bin_len = 0, checksum = 0;
  f.read(reinterpret_cast<char*>(&key_len), sizeof key_len);
  if (!f || magic != kMagic || key_len > (1u << 20)) {
    why = "bad header";
    return false;
  }
  std::string stored_key(key_len, '\0');
  f.read(&stored_key[0], static_cast<std::streamsize>(key_len));
  f.read(reinterpret_cast<char*>(&bin_len), sizeof bin_len);
  f.read(reinterpret_cast<char*>(&checksum), sizeof checksum);
  if (!f || stored_key != key) {
    why = "stale or colliding key";
    return false;
  }
  if (bin_len == 0 || bin_len > (1ull << 31)) {
    why = "bad binary size";
    return false;
  }
  binary.resize(bin_len);
  f.read(reinterpret_cast<char*>(binary.data()), static_cast<std::streamsize>(bin_len));
  if (!f || f.peek() != std::char_traits<char>::eof()) {
    why = "truncated or oversized entry";
    return false;
  }
  if (fnv1a(binary.data(), binary.size()) != checksum) {
    why = "checksum mismatch";
    return false;
  }
  return true;
}

void write_entry(const std::string& path, const std::string& key, const std::vector<unsigned char>& binary) {
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) return;  // an unwritable cache only costs speed
    std::uint64_t key_len = key.size(), bin_len = binary.size();
    std::uint64_t checksum = fnv1a(binary.data(), binary.size());
    f.write(kMagic, sizeof kMagic - 1);
    f.write(reinterpret_cast<const char*>(&key_len), sizeof key_len);
    f.write(key.data(), static_cast<std::streamsize>(key.size()));
    f.write(reinterpret_cast<const char*>(&bin_len), sizeof bin_len);
    f.write(reinterpret_cast<const char*>(&checksum), sizeof checksum);
    f.write(reinterpret_cast<const char*>(binary.data()), static_cast<std::streamsize>(binary.size()));
    if (!f) {
      fs::remove(tmp, ec);
      return;
    }
  }
  fs::rename(tmp, path, ec);  // atomic: readers never see a half-written entry
  if (ec) fs::remove(tmp, ec);
}

/// An exclusive flock on `path` held while alive: processes that miss the same entry at the same
/// time build it once (the others wait, then read what the first wrote) instead of each compiling
/// it. Waits at most `max_wait` seconds (a holder stuck in a driver must not stall every other
/// process), then builds without the lock; any failure to lock only costs a redundant build.
class BuildLock {
 public:
  BuildLock(const std::string& path, double max_wait) {
    std::error_code ec;
    fs::create_directories(fs::path(path).parent_path(), ec);
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) return;
    auto t0 = std::chrono::steady_clock::now();
    while (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      if (errno != EWOULDBLOCK ||
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > max_wait) {
        ::close(fd_);
        fd_ = -1;
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  ~BuildLock() {
    if (fd_ >= 0) ::close(fd_);  // releases the lock
  }
  BuildLock(const BuildLock&) = delete;
  BuildLock& operator=(const BuildLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace

std::string program_cache_dir() {
  const char* env = std::getenv("LUCENT_CACHE_DIR");
  if (env && *env) return std::string(env) == "off" ? std::string() : std::string(env);
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg && *xdg) return std::string(xdg) + "/lucent";
  const char* home = std::getenv("HOME");
  if (home && *home) return std::string(home) + "/.cache/lucent";
  return "";
}

cl::Program build_program_cached(const Context& ctx, const std::string& source, const std::string& options,
                                 ProgramBuildInfo* info) {
  auto t0 = std::chrono::steady_clock::now();
  ProgramBuildInfo local;
  ProgramBuildInfo& bi = info ? *info : local;
  bi = ProgramBuildInfo{};
  std::string dir = program_cache_dir();
  std::string key = cache_key(ctx, source, options);
  auto finish = [&](cl::Program p) {
    bi.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return p;
  };
  std::unique_ptr<BuildLock> lock;
  if (!dir.empty()) {
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
        return true;
      } catch (const cl::Error&) {
        why = "the driver rejected the binary";
        return false;
      }
    };
    cl::Program p;
    if (load(p)) return finish(p);
    // a miss: wait for another process that may be building this entry, then look again
    lock = std::make_unique<BuildLock>(bi.cache_file + ".lock", 600);
    if (load(p)) return finish(p);
    if (!why.empty()) {
      bi.note = bi.cache_file + ": " + why + "; rebuilt";
      std::error_code ec;
      fs::remove(bi.cache_file, ec);
    }
  }
  cl::Program p = build_program(ctx, source, options);
  if (!dir.empty()) {
    try {
      auto bins = p.getInfo<CL_PROGRAM_BINARIES>();
      if (bins.size() == 1 && !bins[0].empty()) write_entry(bi.cache_file, key, bins[0]);
    } catch (const cl::Error&) {
      // some drivers cannot return binaries: no cache, no harm
    }
  }
  return finish(p);
}

int clear_program_cache() {
  std::string dir = program_cache_dir();
  if (dir.empty()) return 0;
  int n = 0;
  std::error_code ec;
  for (auto& e : fs::directory_iterator(dir, ec)) {
    if (e.path().extension() == ".lock") {
      fs::remove(e.path(), ec);  // build locks: not entries, not counted
      continue;
    }
    if (e.path().extension() == ".bin" || e.path().string().find(".bin.tmp.") != std::string::npos) {
      fs::remove(e.path(), ec);
      if (!ec) ++n;
    }
  }
  return n;
}

}  // namespace lucent::cl_util
