#pragma once
// The memory this process may use on the host, for the checks that refuse what would exhaust it
// (the scene's textures as they load, the render's estimate in render/resources.cpp).
#include <cstdint>
#include <string>

namespace lucent::sys {

/// The smallest of physical memory, the address-space limit (RLIMIT_AS, `ulimit -v`) and the
/// cgroup's memory limit (v2 memory.max, v1 memory.limit_in_bytes), with which of them it is
/// ("physical memory", ...). bytes is 0 when none is known.
struct HostMemory {
  std::uint64_t bytes = 0;
  std::string what;
  /// What lucent allows itself: 80% of it.
  std::uint64_t limit() const { return bytes / 5 * 4; }
};
HostMemory host_memory();

/// What lucent allows itself: 80% of host_memory() (0 when unknown).
std::uint64_t host_memory_limit();

/// host_memory_limit(), lowered to a test's override where one is set (`what`: what the limit is
/// 80% of). The memory checks of every layer use it (render_detail::ScopedLimitOverride sets the
/// override).
std::uint64_t host_memory_allowed(std::string* what);

/// Tests: a lower host limit for host_memory_allowed (0: none).
void set_host_limit_override(std::uint64_t bytes);

/// Gives the heap's free pages back to the system (glibc's malloc_trim; nothing elsewhere): after
/// a large load or build whose temporaries were freed in many pieces, which glibc keeps resident
/// (an OBJ soup of 10^6 triangles left 70 MB of the loader's arrays).
void return_free_memory();

/// Byte counts for the memory checks: a * b and a + b, or the largest count where they overflow.
/// A film's pixels reach 2^62 (two 31-bit sides), so a count in bytes can pass 64 bits: wrapped,
/// a 2147352580x536903681 film counted 3783 bytes and passed the check.
std::uint64_t bytes_mul(std::uint64_t a, std::uint64_t b);
std::uint64_t bytes_add(std::uint64_t a, std::uint64_t b);

/// Bytes as "12.3 GiB", "512.0 MiB", "96.0 KiB", "100 bytes" (TiB, PiB and EiB above); the
/// saturated count 2^64 - 1 as "16.0 EiB or more".
std::string format_bytes(std::uint64_t bytes);

}  // namespace lucent::sys
