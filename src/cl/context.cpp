#include "cl/context.hpp"

#include <pthread.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <sstream>

#include "cl/kernel_source.hpp"
#include "lucent/error.hpp"

namespace lucent::cl_util {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\0' || std::isspace(static_cast<unsigned char>(s.back()))))
    s.pop_back();
  size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

std::string type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "GPU";
  if (t & CL_DEVICE_TYPE_CPU) return "CPU";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

// "0 'name' (CPU), 1 'name' (GPU)": the devices an error about a selector lists.
std::string device_list(const std::vector<Device>& devices) {
  std::string out;
  for (const Device& d : devices)
    out += (out.empty() ? "" : ", ") + std::to_string(d.info.index) + " '" + d.info.name + "' (" +
           d.info.type + ")";
  return out;
}

size_t skip_digits(const std::string& s, size_t at) {
  while (at < s.size() && std::isdigit(static_cast<unsigned char>(s[at]))) ++at;
  return at;
}

}  // namespace

std::string source_place(const std::string& source, long line) {
  if (line < 1) return "";
  std::istringstream in(source);
  std::string file, text;
  long logical = 0;  // the logical line of the current physical line
  bool reached = false;
  for (long physical = 1; std::getline(in, text); ++physical, ++logical) {
    if ((reached = physical == line)) break;
    if (text.rfind("#line ", 0) == 0) {  // #line N "file": the next line is line N of file
      size_t n0 = 6, n1 = skip_digits(text, n0);
      size_t q1 = text.find('"', n1), q2 = q1 == std::string::npos ? q1 : text.find('"', q1 + 1);
      if (n1 == n0 || q2 == std::string::npos) continue;
      logical = std::strtol(text.c_str() + n0, nullptr, 10) - 1;
      file = text.substr(q1 + 1, q2 - q1 - 1);
    }
  }
  if (!reached || file.empty()) return "";
  return file + ":" + std::to_string(logical);
}

std::string map_source_places(const std::string& log, const std::string& source) {
  std::istringstream in(log);
  std::string out;
  for (std::string line; std::getline(in, line);) {
    // "<name>:<line>:<col>: ..." where <name> is not a kernels/ path: the physical line
    size_t colon = line.find(':');
    size_t e = colon == std::string::npos ? colon : skip_digits(line, colon + 1);
    size_t c = e == std::string::npos || e >= line.size() || line[e] != ':'
                   ? std::string::npos
                   : skip_digits(line, e + 1);
    if (colon != std::string::npos && colon > 0 && line.find(' ') > colon &&
        line.rfind("kernels/", 0) != 0 && e > colon + 1 && c != std::string::npos && c > e + 1 &&
        line.compare(c, 2, ": ") == 0) {
      std::string place = source_place(source, std::strtol(line.c_str() + colon + 1, nullptr, 10));
      if (!place.empty()) line = place + line.substr(e);
    }
    out += (out.empty() ? "" : "\n") + line;
  }
  return out;
}

std::string first_error_place(const std::string& log) {
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);) {
    if (line.find("error") == std::string::npos) continue;
    for (auto k = line.find("kernels/"); k != std::string::npos; k = line.find("kernels/", k + 1)) {
      // kernels/<file>:<line>[:<col>]
      size_t file_end = line.find(':', k + 8), e = file_end;
      if (file_end == std::string::npos || (e = skip_digits(line, file_end + 1)) == file_end + 1)
        continue;
      if (e < line.size() && line[e] == ':' && skip_digits(line, e + 1) > e + 1)
        e = skip_digits(line, e + 1);
      return line.substr(k, e - k);
    }
  }
  return "";
}

std::string pocl_cache_dir(std::string* origin) {
  // as pocl_cache_init_topdir: POCL_CACHE_DIR, else $XDG_CACHE_HOME/pocl/kcache, else
  // $HOME/.cache/pocl/kcache, else /tmp/pocl/kcache ("uncached" for "kcache" with
  // POCL_KERNEL_CACHE off)
  std::string from;
  std::string dir;
  if (const char* v = std::getenv("POCL_CACHE_DIR"); v && *v) {
    dir = v;
    from = "POCL_CACHE_DIR";
  } else {
    const char* cache = std::getenv("POCL_KERNEL_CACHE");
    const std::string sub = cache && cache[0] != '1' ? "pocl/uncached" : "pocl/kcache";
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    const char* home = std::getenv("HOME");
    if (xdg && *xdg) {
      dir = std::string(xdg) + "/" + sub;
      from = "XDG_CACHE_HOME=" + std::string(xdg);
    } else if (home) {
      dir = std::string(home) + "/.cache/" + sub;
      from = "HOME=" + std::string(home);
    } else {
      dir = "/tmp/" + sub;
      from = "HOME unset";
    }
  }
  if (origin) *origin = from;
  return dir;
}

namespace {

/// PoCL's cache directory as messages name it: "POCL_CACHE_DIR=/x", or "PoCL's cache directory
/// /home/u/.cache/pocl/kcache (HOME=/home/u)" with what chose it.
std::string pocl_cache_dir_name(const std::string& dir, const std::string& origin) {
  return origin == "POCL_CACHE_DIR" ? "POCL_CACHE_DIR=" + dir
                                    : "PoCL's cache directory " + dir + " (" + origin + ")";
}

}  // namespace

std::string pocl_cache_dir_problem() {
  namespace fs = std::filesystem;
  // the directory PoCL uses, not only POCL_CACHE_DIR: an XDG_CACHE_HOME that was a file or
  // read-only gave "no OpenCL device found on any platform" and nothing more
  std::string origin;
  const std::string dir = pocl_cache_dir(&origin);
  const std::string name = pocl_cache_dir_name(dir, origin);
  std::error_code ec;
  fs::path p(dir);
  // the directory itself, else the nearest ancestor that exists (PoCL creates the rest)
  while (!fs::exists(fs::symlink_status(p, ec)) && p.has_parent_path() && p != p.parent_path())
    p = p.parent_path();
  if (!fs::exists(p, ec)) return name + " cannot be created";
  if (!fs::is_directory(p, ec))
    return name + (p == fs::path(dir)
                       ? " is not a directory"
                       : " cannot be created (" + p.string() + " is not a directory)");
  if (::access(p.c_str(), W_OK | X_OK) != 0)
    return name + (p == fs::path(dir) ? " is not writable" : " cannot be created") + " (" +
           std::strerror(errno) + ")";
  // where permissions do not tell (root, /proc): make it as PoCL would (called on errors only)
  if (p != fs::path(dir) && !fs::create_directories(dir, ec) && ec)
    return name + " cannot be created (" + ec.message() + ")";
  // a full disk: PoCL writes the kernel's source, bitcode and shared object there (a few MiB);
  // its build failed with an empty log
  return pocl_cache_space_problem(16.0 * 1024 * 1024);
}

std::string pocl_cache_space_problem(double min_bytes) {
  namespace fs = std::filesystem;
  std::string origin;
  const std::string dir = pocl_cache_dir(&origin);
  // the directory, else the nearest ancestor that exists (a first build into a new directory
  // on a full disk: the review's find)
  std::error_code ec;
  fs::path p(dir);
  while (!fs::exists(p, ec) && p.has_parent_path() && p != p.parent_path()) p = p.parent_path();
  struct statvfs fsinfo {};
  if (::statvfs(p.c_str(), &fsinfo) != 0) return "";
  const double free_bytes = double(fsinfo.f_bavail) * double(fsinfo.f_frsize);
  if (free_bytes >= min_bytes) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.0f KiB", free_bytes / 1024.0);
  return pocl_cache_dir_name(dir, origin) + " has only " + buf + " free";
}

namespace {

// PoCL keeps its kernels and temporary files in POCL_CACHE_DIR: when it cannot use that
// directory it lists no device, or fails every build with an empty log. Errors that PoCL may
// have caused name the directory's problem.
std::string pocl_cache_hint() {
  std::string problem = pocl_cache_dir_problem();
  return problem.empty() ? "" : "; " + problem + ", which PoCL needs for its kernels";
}

// No platform: no driver is installed, or one failed to load. NVIDIA's fails under an
// address-space limit of a few GiB (the CUDA driver reserves more address space than that), so
// the message names a limit when one is set.
std::string no_platform() {
  std::string msg =
      "no OpenCL platform found: install an OpenCL driver (Debian: pocl-opencl-icd for the CPU)";
  struct rlimit lim {};
  if (::getrlimit(RLIMIT_AS, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY) {
    std::ostringstream gib;
    gib.precision(3);
    gib << static_cast<double>(lim.rlim_cur) / (1024.0 * 1024.0 * 1024.0);
    msg += ", or raise the address-space limit (ulimit -v, now " + gib.str() +
           " GiB), which can keep an installed driver from loading (NVIDIA's does)";
  }
  return msg + pocl_cache_hint();
}

}  // namespace

std::string pocl_thread_count_problem() {
  const char* v = std::getenv("POCL_MAX_PTHREAD_COUNT");
  if (!v || !*v) return "";
  // PoCL reads it with atoi and starts that many threads when it initialises:
  // a negative value (or one that wraps to it) crashed the process (SIGSEGV), 100000 aborted it
  // ("PTHREAD ERROR in pthread_scheduler_init(): Resource temporarily unavailable")
  errno = 0;
  char* end = nullptr;
  const long long n = std::strtoll(v, &end, 10);  // as atoi
  if (end == v) return "";  // not a number: PoCL takes it as 0 and uses one thread
  if (errno == ERANGE || n < 0 || n > kMaxPoclThreads)
    return std::string("POCL_MAX_PTHREAD_COUNT=") + v +
           ": PoCL crashes with a negative or huge thread count; give 1 to " +
           std::to_string(kMaxPoclThreads) + ", or unset it (one thread per CPU)";
  return "";
}

std::string pocl_empty_cache_dir_problem() {
  const char* v = std::getenv("POCL_CACHE_DIR");
  if (!v || *v) return "";
  return "POCL_CACHE_DIR is set but empty, which PoCL aborts on: unset it or name a directory";
}

namespace {
std::atomic<bool> g_forked_after_opencl{false};
void on_fork_child() { g_forked_after_opencl.store(true); }
}  // namespace

bool forked_after_opencl() { return g_forked_after_opencl.load(); }

namespace {
/// Keeps the process's own SIGINT, SIGTERM and SIGHUP handlers across OpenCL calls that
/// initialise a driver: PoCL's LLVM installs its own over them (SA_RESETHAND, and it gives the
/// signal to the saved handler only after it cleaned up), at PoCL's first enumeration, and keeps
/// them. Two signals microseconds apart (GNU timeout's) then found the default action in between
/// and killed lucent with no word, also during a later kernel build, and Python's SIGINT handler
/// stayed behind LLVM's for the module's life. LLVM registers its handlers once: given back here,
/// they stay the process's (until a signal of LLVM's own kind, SIGSEGV and such, unregisters it).
class KeepStopHandlers {
 public:
  KeepStopHandlers() {
    for (int i = 0; i < 3; ++i) ::sigaction(kSignals[i], nullptr, &saved_[i]);
  }
  ~KeepStopHandlers() {
    // only over LLVM's (its mark: SA_RESETHAND where the process's had none): a handler another
    // thread of the application set meanwhile (Python's signal.signal while a Renderer is made
    // without the GIL) stays
    for (int i = 0; i < 3; ++i) {
      struct sigaction now {};
      ::sigaction(kSignals[i], nullptr, &now);
      if ((now.sa_flags & SA_RESETHAND) && !(saved_[i].sa_flags & SA_RESETHAND))
        ::sigaction(kSignals[i], &saved_[i], nullptr);
    }
  }
  KeepStopHandlers(const KeepStopHandlers&) = delete;
  KeepStopHandlers& operator=(const KeepStopHandlers&) = delete;

 private:
  static constexpr int kSignals[3] = {SIGINT, SIGTERM, SIGHUP};
  struct sigaction saved_[3]{};
};
}  // namespace

void check_not_forked() {
  if (g_forked_after_opencl.load())
    throw Error(
        "this process is a fork of one that had used OpenCL, whose driver threads do not survive "
        "a fork (OpenCL calls would hang): use lucent in the parent only after the workers are "
        "forked, or start them with spawn or forkserver (Python: "
        "multiprocessing.get_context(\"spawn\"))");
}

std::vector<Device> enumerate_devices() {
  check_not_forked();
  // one enumeration at a time in the process: the ICD loader and PoCL initialise on the first
  // call, and sessions created at once from several threads crashed there (SIGSEGV) or saw no
  // platform
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  // before PoCL reads it (it is read once, on the first call)
  if (std::string problem = pocl_thread_count_problem(); !problem.empty()) throw Error(problem);
  if (std::string problem = pocl_empty_cache_dir_problem(); !problem.empty()) throw Error(problem);
  // a child forked from here on is recorded: its OpenCL calls would hang (check_not_forked)
  static std::once_flag fork_handler;
  std::call_once(fork_handler, [] { ::pthread_atfork(nullptr, nullptr, on_fork_child); });
  const KeepStopHandlers keep;  // PoCL initialises in the calls below
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error& e) {
    if (e.err() == -1001 || e.err() == CL_INVALID_VALUE) throw Error(no_platform());
    throw Error(describe(e));
  }
  if (platforms.empty()) throw Error(no_platform());
  std::vector<Device> out;
  try {
    for (auto& p : platforms) {
      std::vector<cl::Device> devices;
      try {
        p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
      } catch (const cl::Error& e) {
        if (e.err() == CL_DEVICE_NOT_FOUND) continue;
        throw;
      }
      for (auto& d : devices) {
        Device dev{p, d, {}};
        DeviceInfo& i = dev.info;
        i.index = static_cast<int>(out.size());
        i.platform = trim(p.getInfo<CL_PLATFORM_NAME>());
        i.name = trim(d.getInfo<CL_DEVICE_NAME>());
        i.type = type_name(d.getInfo<CL_DEVICE_TYPE>());
        i.vendor = trim(d.getInfo<CL_DEVICE_VENDOR>());
        i.driver_version = trim(d.getInfo<CL_DRIVER_VERSION>());
        i.opencl_c_version = trim(d.getInfo<CL_DEVICE_OPENCL_C_VERSION>());
        i.compute_units = d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
        i.global_memory = d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
        std::string ext = d.getInfo<CL_DEVICE_EXTENSIONS>();
        i.fp64 = ext.find("cl_khr_fp64") != std::string::npos;
        i.int64_atomics = ext.find("cl_khr_int64_base_atomics") != std::string::npos;
        if (!i.fp64) {
          // fp64 is optional: the extension, or (OpenCL 1.2+) a non-empty double FP config; a
          // driver that rejects the query has none
          try {
            i.fp64 = d.getInfo<CL_DEVICE_DOUBLE_FP_CONFIG>() != 0;
          } catch (const cl::Error&) {
          }
        }
        out.push_back(std::move(dev));
      }
    }
  } catch (const cl::Error& e) {
    throw Error(describe(e));
  }
  if (out.empty()) throw Error("no OpenCL device found on any platform" + pocl_cache_hint());
  return out;
}

int device_by_name(const std::vector<DeviceInfo>& devices, const std::string& selector) {
  // a device's whole name picks it even where it is part of another's name (Intel's CPU runtime
  // names its device "Intel(R) Xeon(R) Processor", PoCL the same CPU
  // "pthread-skylake-avx512-Intel(R) Xeon(R) Processor"); else the first name containing it
  const std::string want = lower(selector);
  for (size_t i = 0; i < devices.size(); ++i)
    if (lower(devices[i].name) == want) return static_cast<int>(i);
  for (size_t i = 0; i < devices.size(); ++i)
    if (lower(devices[i].name).find(want) != std::string::npos) return static_cast<int>(i);
  return -1;
}

Device pick_device(const std::string& given, const std::string& origin) {
  auto devices = enumerate_devices();
  // spaces around it, as around a list's items (' 0' matched no name, where '0, 0' was taken)
  const std::string trimmed = trim(given);
  const std::string& selector = trimmed.empty() ? given : trimmed;
  if (selector.empty()) {
    for (auto& d : devices)
      if (d.info.type == "GPU") return d;
    for (auto& d : devices)
      if (d.info.type == "CPU") return d;
    return devices.front();
  }
  bool numeric = std::all_of(selector.begin(), selector.end(),
                             [](unsigned char c) { return std::isdigit(c); });
  if (numeric) {
    long index = std::strtol(selector.c_str(), nullptr, 10);
    if (index >= 0 && index < static_cast<long>(devices.size())) return devices[index];
    throw Error(origin + " " + selector +
                ": no device with this index (available: " + device_list(devices) + ")");
  }
  std::string want = lower(selector);
  if (trim(want).empty())
    throw Error(origin + " '" + selector +
                "': empty device selector (available: " + device_list(devices) + ")");
  std::vector<DeviceInfo> infos;
  for (const auto& d : devices) infos.push_back(d.info);
  const int i = device_by_name(infos, selector);
  if (i >= 0) return devices[i];
  throw Error(origin + " '" + selector +
              "': no device name contains it (available: " + device_list(devices) + ")");
}

Context::Context(const std::string& selector, const std::string& origin)
    : device(pick_device(selector, origin)) {
  const KeepStopHandlers keep;
  try {
    context = cl::Context(device.device);
    queue = cl::CommandQueue(context, device.device);
  } catch (const cl::Error& e) {
    throw Error(describe(e));
  }
}

cl::Program build_program(const Context& ctx, const std::string& source,
                          const std::string& options) {
  const KeepStopHandlers keep;  // (LLVM registers again after one of its handlers ran)
  // PoCL's compiler writes the kernel's files in its cache directory, and on a full disk LLVM
  // ended the process ("LLVM ERROR: IO failure on output stream: No space left on device"),
  // before any message of lucent's: refused first (4 MiB: a cold build writes about 2-5 MiB)
  if (is_pocl(ctx.device.info)) {
    const std::string problem = pocl_cache_space_problem(4.0 * 1024 * 1024);
    if (!problem.empty())
      throw Error("kernel build: " + problem +
                  ", which PoCL needs for its kernels (free space there, or set POCL_CACHE_DIR "
                  "to another directory)");
    // and a file size limit under which no build writes its files, even from a warm cache (ulimit
    // -f 20: LLVM's "IO failure on output stream", or a build failure naming no cause); between
    // 1 and about 5 MiB a cold build can still fail so, a warm one not
    struct rlimit fsize {};
    if (::getrlimit(RLIMIT_FSIZE, &fsize) == 0 && fsize.rlim_cur != RLIM_INFINITY &&
        fsize.rlim_cur < (rlim_t(1) << 20))
      throw Error("kernel build: the file size limit (ulimit -f) is " +
                  std::to_string(fsize.rlim_cur / 1024) +
                  " KiB, less than PoCL's compiler writes for a kernel (a few MiB): raise it");
  }
  cl::Program program;
  try {
    program = cl::Program(ctx.context, source);
  } catch (const cl::Error& e) {
    throw Error(describe(e));
  }
  try {
    program.build({ctx.device.device}, options.c_str());
  } catch (const cl::Error& e) {
    std::string log;
    try {
      log = trim(program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(ctx.device.device));
    } catch (const cl::Error&) {
    }
    log = map_source_places(log, source);
    std::string place = first_error_place(log);
    std::string msg = (place.empty() ? std::string() : place + ": ") +
                      "kernel build failed: " + describe(e) +
                      (log.empty() ? "" : " (build log above)");
    if (place.empty() && is_pocl(ctx.device.info))
      msg += pocl_cache_hint();  // no error in the source: perhaps PoCL's directory
    throw Error(msg, log.empty() ? std::string() : "kernel build log:\n" + log);
  }
  return program;
}

}  // namespace lucent::cl_util

namespace lucent {

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  for (auto& d : cl_util::enumerate_devices()) out.push_back(d.info);
  return out;
}

DeviceInfo select_device(const std::string& selector, const std::string& origin) {
  return cl_util::pick_device(selector, origin).info;
}

std::vector<DeviceInfo> select_devices(const std::string& selectors, const std::string& origin) {
  if (cl_util::lower(cl_util::trim(selectors)) == "all") return list_devices();
  std::vector<DeviceInfo> out;
  if (selectors.find(',') == std::string::npos) {
    out.push_back(select_device(selectors, origin));
    return out;
  }
  std::string item;
  for (size_t i = 0; i <= selectors.size(); ++i) {
    if (i < selectors.size() && selectors[i] != ',') {
      item += selectors[i];
      continue;
    }
    size_t b = item.find_first_not_of(' '), e = item.find_last_not_of(' ');
    if (b == std::string::npos)
      throw Error(origin + " '" + selectors + "': an empty selector in the list");
    const std::string selector = item.substr(b, e - b + 1);
    if (cl_util::lower(selector) == "all")
      throw Error(origin + " '" + selectors +
                  "': 'all' selects every device and stands alone, not in a list");
    out.push_back(select_device(selector, origin));
    item.clear();
  }
  return out;
}

}  // namespace lucent
