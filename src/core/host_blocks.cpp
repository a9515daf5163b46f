#include "core/host_blocks.hpp"

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <unordered_map>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "core/text.hpp"
#include "scene/loaders.hpp"  // scene_detail::warn

namespace lucent::sys {

namespace {

struct Block {
  std::size_t bytes = 0;  ///< what it holds (a multiple of kHugePageBytes)
  int refs = 0;
};

/// The live blocks by address. Never destroyed: an OpenCL driver may release a buffer, and with
/// it a block, from its own thread as the process exits.
struct Registry {
  std::mutex mutex;
  std::unordered_map<const void*, Block> blocks;
  std::uint64_t bytes = 0;
};
Registry& registry() {
  static Registry* r = new Registry;
  return *r;
}

bool huge_pages_wanted() {
  const char* e = std::getenv("LUCENT_HUGE_PAGES");
  if (!e || !*e || std::strcmp(e, "1") == 0) return true;
  if (std::strcmp(e, "0") == 0) return false;
  // ("off", "false", "no" turned them on without a word); once, through the warning sink of the
  // call that allocates (a session's on_warning, Python's warnings), as the other variables'
  static std::atomic<bool> said{false};
  if (!said.exchange(true))
    scene_detail::warn("LUCENT_HUGE_PAGES='" + io::one_line(e) +
                       "' is neither 0 (no huge-page advice) nor 1 (the default); taken as 1");
  return true;
}

}  // namespace

std::uint64_t host_block_bytes(std::uint64_t bytes) {
  if (bytes < kHugePageMinBuffer) return bytes;
  if (bytes > ~std::uint64_t(0) - kHugePageBytes) return ~std::uint64_t(0);  // a saturated count
  return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
}

void* allocate_host_block(std::size_t bytes) {
  const std::size_t size = host_block_bytes(bytes);
  void* p = std::aligned_alloc(kHugePageBytes, size);
  if (!p) return nullptr;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  // before the first touch, so that the pages are huge as they are faulted in; advice only:
  // refused, the block keeps ordinary pages
  if (huge_pages_wanted()) madvise(p, size, MADV_HUGEPAGE);
#endif
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  try {
    r.blocks.emplace(p, Block{size, 1});
  } catch (...) {
    std::free(p);
    return nullptr;
  }
  r.bytes += size;
  return p;
}

bool retain_host_block(const void* p, std::size_t bytes) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto it = r.blocks.find(p);
  if (it == r.blocks.end() || it->second.bytes < bytes) return false;
  ++it->second.refs;
  return true;
}

void release_host_block(void* p) {
  if (!p) return;
  Registry& r = registry();
  {
    std::lock_guard<std::mutex> lock(r.mutex);
    auto it = r.blocks.find(p);
    if (it == r.blocks.end()) std::abort();  // not a block: a bug, not a case to go on with
    if (--it->second.refs > 0) return;
    r.bytes -= it->second.bytes;
    r.blocks.erase(it);
  }
  std::free(p);
}

int host_blocks() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  return static_cast<int>(r.blocks.size());
}

std::uint64_t host_block_total() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  return r.bytes;
}

}  // namespace lucent::sys
