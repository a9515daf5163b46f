#pragma once
// Host blocks of whole huge pages for large arrays that an OpenCL CPU device reads in place.
//
// A CPU device's buffers are host memory, and every ray reads the scene's BVH, triangles and
// texels at random: over megabytes of 4 KiB pages most of those reads miss the TLB as well. An
// array of kHugePageMinBuffer bytes or more that HugePageAllocator allocates therefore lives in a
// block aligned to 2 MiB, rounded up to whole 2 MiB, and advised as transparent huge pages
// (Linux's MADV_HUGEPAGE: used when /sys/kernel/mm/transparent_hugepage/enabled says "madvise",
// Debian's default, or "always"; LUCENT_HUGE_PAGES=0 gives no advice). Dragon box: about 1.05x
// the samples per second (BENCHMARKS.md).
//
// The blocks are reference counted, so that a CPU device's buffer made over one (CL_MEM_USE_HOST_
// PTR, render/device_scene.cpp) holds it as long as the buffer lives, whatever happens to the
// array: the session's packed scene and its CPU devices' buffers then share one copy of the scene
// (a 10^6-triangle soup held 346 MB twice), and no buffer outlives its storage, on any path.
#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

namespace lucent::sys {

constexpr std::size_t kHugePageBytes = std::size_t(2) << 20;
/// Arrays (and buffers) of this many bytes or more take huge-page blocks.
constexpr std::size_t kHugePageMinBuffer = std::size_t(1) << 20;

/// The host memory an array of `bytes` takes: whole huge pages from kHugePageMinBuffer bytes.
std::uint64_t host_block_bytes(std::uint64_t bytes);

/// A new block of host_block_bytes(bytes) (bytes >= kHugePageMinBuffer) with one reference;
/// nullptr when the memory could not be had.
void* allocate_host_block(std::size_t bytes);
/// Takes another reference to the block that starts at `p` and holds at least `bytes`: true, or
/// false when `p` is no such block (then nothing changed).
bool retain_host_block(const void* p, std::size_t bytes);
/// Drops a reference to the block at `p`, freeing it with the last one.
void release_host_block(void* p);

/// Blocks alive now, and the bytes they hold. For tests.
int host_blocks();
std::uint64_t host_block_total();

/// std::allocator, except that allocations of kHugePageMinBuffer bytes or more are host blocks
/// (released, not freed: a buffer may still hold the block).
template <class T>
struct HugePageAllocator {
  using value_type = T;
  static_assert(alignof(T) <= __STDCPP_DEFAULT_NEW_ALIGNMENT__, "plain operator new suffices");
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePageMinBuffer) return static_cast<T*>(::operator new(bytes));
    void* p = allocate_host_block(bytes);
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    // the same size as allocate's: a block exactly when that was one
    if (n * sizeof(T) < kHugePageMinBuffer)
      ::operator delete(p);
    else
      release_host_block(p);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
  template <class U>
  bool operator!=(const HugePageAllocator<U>&) const noexcept {
    return false;
  }
};

/// A vector whose large storage is a host block (the packed scene's arrays, pack.hpp).
template <class T>
using HostVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace lucent::sys
