/* lucent test kernel: reports sizeof/offsetof of the shared structs as the device compiles them.
 * tests/test_layout.cpp compares each value with the host's. The order of the entries is the
 * order of LUCENT_LAYOUT_ENTRIES in src/cl/layout.hpp. */
#include "shared/types.h"

#define LC_SIZE(t) (lc_uint)sizeof(t)
#define LC_OFF(t, m) (lc_uint) LC_OFFSETOF(t, m)

__kernel void lucent_layout_probe(__global lc_uint* out) {
  int i = 0;
#define LUCENT_LAYOUT_SIZE(t) out[i++] = LC_SIZE(t);
#define LUCENT_LAYOUT_OFFSET(t, m) out[i++] = LC_OFF(t, m);
#define LUCENT_LAYOUT_ALIGN(t) out[i++] = (lc_uint) __alignof__(t);
#include "shared/layout_entries.h"
}
