#pragma once
// Launches of the test kernels (kernels/test/*.cl).
#include <cstddef>

#include "cl/context.hpp"

namespace lucent::test {

/// Launches `k` over `n` work-items in work-groups of 64 where `n` is a multiple of 64, else of
/// one. PoCL compiles a work-group function for each local size it meets, and the size it picks
/// when none is given follows `n`: the light probe's launches of 2001 to 4096 items compiled
/// eight functions of one kernel, 142 functions for 99 programs over the suite (docs/testing.md);
/// now at most two per kernel.
inline void launch_probe(cl::CommandQueue& q, const cl::Kernel& k, std::size_t n) {
  const std::size_t local = n % 64 == 0 ? 64 : 1;
  q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n), cl::NDRange(local));
}

}  // namespace lucent::test
