#pragma once
// Launches of the test kernels (kernels/test/*.cl).
#include <cstddef>
#include <vector>

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

/// Sets `k`'s arguments first, first + 1, ... to `args` (buffers, scalars, structs) and returns
/// the index after the last: `set_args(k, 0, in, n, out)`, or after a scene's arguments
/// `set_args(k, dev.set_args(k), p, in, out)`.
template <class... Args>
cl_uint set_args(cl::Kernel& k, cl_uint first, const Args&... args) {
  (k.setArg(first++, args), ...);
  return first;
}

/// The first `n` elements of `b`, read with a blocking read.
template <class T>
std::vector<T> read_back(cl::CommandQueue& q, const cl::Buffer& b, std::size_t n) {
  std::vector<T> out(n);
  if (n > 0) q.enqueueReadBuffer(b, CL_TRUE, 0, n * sizeof(T), out.data());
  return out;
}

}  // namespace lucent::test
