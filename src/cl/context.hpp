#pragma once
#include <string>
#include <vector>

#include "cl/opencl.hpp"
#include "cl/pocl.hpp"
#include "lucent/device.hpp"

namespace lucent::cl_util {

struct Device {
  cl::Platform platform;
  cl::Device device;
  DeviceInfo info;
};

/// Every device of every platform, in `lucent devices` order. Throws lucent::Error.
std::vector<Device> enumerate_devices();

/// See lucent::select_device; "" picks the first GPU, else the first CPU device. Errors name
/// `origin`, where the selector came from ("--device", "LUCENT_DEVICE", ...).
Device pick_device(const std::string& selector, const std::string& origin = "--device");

/// The device a name selector picks among `devices` (its index), or -1: the device whose whole
/// name it is (case-insensitive), else the first whose name contains it.
int device_by_name(const std::vector<DeviceInfo>& devices, const std::string& selector);

/// A context and an in-order queue on one device.
struct Context {
  Device device;
  cl::Context context;
  cl::CommandQueue queue;
  explicit Context(const std::string& selector, const std::string& origin = "--device");
};

/// "kernels/<file>:<line>" of physical line `line` (from 1) of an assembled source, by its #line
/// markers; empty before the first marker.
std::string source_place(const std::string& source, long line);

/// A build log with every "<name>:<line>:<col>: " that gives a physical line of `source` (NVIDIA's
/// compiler writes "<kernel>:3417:1: error: ...", ignoring #line) replaced by the place the #line
/// markers give, "kernels/<file>:<line>:<col>: "; lines that already name kernels/ stay as they
/// are.
std::string map_source_places(const std::string& log, const std::string& source);

/// The first "kernels/<file>:<line>:<col>: error" of a build log, as "kernels/<file>:<line>:<col>"
/// (the session names the kernel directory in use instead of kernels/ when there is one).
std::string first_error_place(const std::string& log);

/// The most threads POCL_MAX_PTHREAD_COUNT may ask PoCL for.
constexpr long long kMaxPoclThreads = 4096;

/// "" unless POCL_MAX_PTHREAD_COUNT is a number PoCL crashes with (negative, or above
/// kMaxPoclThreads: it starts that many threads, or wraps to a negative int); then the error
/// enumerate_devices() throws before any OpenCL call.
std::string pocl_thread_count_problem();

/// "" unless POCL_CACHE_DIR is set but empty, which PoCL aborts on when it initialises (an
/// assertion in pocl_cache_init_topdir: `lucent devices` ended with SIGABRT, and so did the
/// Python interpreter); then the error enumerate_devices() throws before any OpenCL call.
std::string pocl_empty_cache_dir_problem();

/// The directory PoCL keeps its kernels in, as PoCL chooses it: POCL_CACHE_DIR, else
/// $XDG_CACHE_HOME/pocl/kcache, else $HOME/.cache/pocl/kcache, else /tmp/pocl/kcache
/// (pocl/uncached with POCL_KERNEL_CACHE off). `origin`, when given: "POCL_CACHE_DIR",
/// "XDG_CACHE_HOME=<value>", "HOME=<value>" or "HOME unset".
std::string pocl_cache_dir(std::string* origin = nullptr);

/// What keeps PoCL from using its kernel cache directory (POCL_CACHE_DIR when set, else as PoCL
/// chooses it: $XDG_CACHE_HOME/pocl/kcache, $HOME/.cache/pocl/kcache): "" when nothing does,
/// else e.g. "POCL_CACHE_DIR=/dev/null is not a directory", "PoCL's cache directory
/// /ro/pocl/kcache (XDG_CACHE_HOME=/ro) cannot be created (Read-only file system)", "... has only
/// 12 KiB free". PoCL then lists no device or fails every build; those errors name it. Creates
/// the directory, as PoCL would, when only trying tells whether it can be made.
std::string pocl_cache_dir_problem();

/// "POCL_CACHE_DIR=... has only N KiB free" when PoCL's cache directory (pocl_cache_dir) has less
/// than `min_bytes` free, "" otherwise (or when it cannot be looked at).
std::string pocl_cache_space_problem(double min_bytes);

/// Throws lucent::Error in a process forked from one that had used OpenCL (enumerate_devices()
/// registers the fork handler that records it): the drivers' threads (PoCL's workers) do not
/// survive a fork, and OpenCL calls there hang for ever (a Python multiprocessing worker of the
/// default start method, forked from a parent that had listed devices or rendered).
void check_not_forked();
/// Whether this process is such a fork (its sessions' OpenCL objects are left unreleased:
/// releasing them hung too).
bool forked_after_opencl();

/// Builds `source` (already assembled, with #line markers) for the context's device. On a build
/// failure throws lucent::Error holding the build log, whose lines name kernels/<file>:<line>,
/// followed by "clBuildProgram: CL_BUILD_PROGRAM_FAILURE".
cl::Program build_program(const Context& ctx, const std::string& source,
                          const std::string& options);

}  // namespace lucent::cl_util
