#include "core/host_memory.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace lucent::sys {

namespace {

/// A cgroup memory limit file's value (0: none, "max" or unreadable).
std::uint64_t read_limit(const std::string& path) {
  std::ifstream f(path);
  unsigned long long v = 0;
  if (!(f >> v) || v >= (1ull << 62)) return 0;
  return v;
}

/// The memory limit of this process's cgroup (v2, then v1), 0 when none.
std::uint64_t cgroup_limit() {
  std::ifstream f("/proc/self/cgroup");
  std::string line;
  while (std::getline(f, line)) {
    const auto colon = line.find(':'), second = line.find(':', colon + 1);
    if (colon == std::string::npos || second == std::string::npos) continue;
    const std::string controllers = line.substr(colon + 1, second - colon - 1);
    std::string path = line.substr(second + 1);
    if (path == "/") path.clear();
    std::uint64_t v = 0;
    if (line.rfind("0::", 0) == 0)
      v = read_limit("/sys/fs/cgroup" + path + "/memory.max");
    else if (("," + controllers + ",").find(",memory,") != std::string::npos)
      v = read_limit("/sys/fs/cgroup/memory" + path + "/memory.limit_in_bytes");
    if (v > 0) return v;
  }
  return 0;
}

}  // namespace

HostMemory host_memory() {
  HostMemory m;
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0) m = {std::uint64_t(pages) * std::uint64_t(page), "physical memory"};
  auto lower = [&](std::uint64_t v, const char* what) {
    if (v > 0 && (m.bytes == 0 || v < m.bytes)) m = {v, what};
  };
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
    lower(rl.rlim_cur, "the address-space limit (ulimit -v)");
  lower(cgroup_limit(), "the cgroup's memory limit");
  return m;
}

std::uint64_t host_memory_limit() { return host_memory().limit(); }

namespace {
std::uint64_t g_host_override = 0;
}  // namespace

std::uint64_t host_memory_allowed(std::string* what) {
  const HostMemory host = host_memory();
  if (what) *what = host.what;
  const std::uint64_t limit = host.limit();
  if (g_host_override == 0) return limit;
  return limit == 0 ? g_host_override : std::min(limit, g_host_override);
}

void set_host_limit_override(std::uint64_t bytes) { g_host_override = bytes; }

std::uint64_t bytes_mul(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r;
  return __builtin_mul_overflow(a, b, &r) ? ~std::uint64_t(0) : r;
}

std::uint64_t bytes_add(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r;
  return __builtin_add_overflow(a, b, &r) ? ~std::uint64_t(0) : r;
}

std::string format_bytes(std::uint64_t bytes) {
  // a saturated count (bytes_mul, bytes_add): not a figure
  if (bytes == ~std::uint64_t(0)) return "16.0 EiB or more";
  char buf[64];
  const double b = double(bytes);
  // (up to 2^64 - 2: "17179869184.0 GiB" beside the saturated count's "16.0 EiB or more")
  if (bytes >= (1ull << 60))
    std::snprintf(buf, sizeof buf, "%.1f EiB", b / double(1ull << 60));
  else if (bytes >= (1ull << 50))
    std::snprintf(buf, sizeof buf, "%.1f PiB", b / double(1ull << 50));
  else if (bytes >= (1ull << 40))
    std::snprintf(buf, sizeof buf, "%.1f TiB", b / double(1ull << 40));
  else if (bytes >= (1ull << 30))
    std::snprintf(buf, sizeof buf, "%.1f GiB", b / double(1ull << 30));
  else if (bytes >= (1ull << 20))
    std::snprintf(buf, sizeof buf, "%.1f MiB", b / double(1ull << 20));
  else if (bytes >= (1ull << 10))
    std::snprintf(buf, sizeof buf, "%.1f KiB", b / double(1ull << 10));
  else
    std::snprintf(buf, sizeof buf, "%llu bytes", static_cast<unsigned long long>(bytes));
  return buf;
}

void return_free_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace lucent::sys
