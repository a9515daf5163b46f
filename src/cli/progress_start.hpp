#pragma once
// When the progress line of `lucent render` and of `lucent-mpi` starts: after a second of
// rendering, so that short renders stay silent. The tests that stop a render with a signal wait
// for that line as their sign that the render loop runs, and so rendered a second or more each
// before their signal; LUCENT_TEST_EARLY_PROGRESS=1, set by them alone (docs/testing.md), starts
// the line sooner.
#include <cstdlib>
#include <cstring>

namespace lucent::cli {

/// Whether LUCENT_TEST_EARLY_PROGRESS is 1: `lucent render`'s progress line starts after its
/// first pass, `lucent-mpi`'s (rank 0's) once every rank has rendered a pass (or ended its render),
/// instead of after a second of rendering. Any other value, or none: the second.
inline bool early_progress_for_tests() {
  const char* v = std::getenv("LUCENT_TEST_EARLY_PROGRESS");
  return v && std::strcmp(v, "1") == 0;
}

}  // namespace lucent::cli
