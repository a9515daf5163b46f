// Fuzz target: the image reader behind `lucent compare` and `converge --reference`
// (lucent::read_render): an OpenEXR with lucent's mean, var.R/G/B and n channels, or any image
// read_image reads (PFM, PNG, ...), from the file's bytes.
#include <cstddef>
#include <cstdint>

#include "fuzz_common.hpp"
#include "image/image_probe.hpp"
#include "lucent/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using lucent::fuzz::check;
  try {
    lucent::RenderResult r = lucent::image_detail::read_render_memory(data, size, "fuzz");
    const size_t n = static_cast<size_t>(r.mean.width) * r.mean.height;
    check(r.mean.width > 0 && r.mean.height > 0 && r.mean.rgb.size() == n * 3, "mean size");
    check(r.variance.rgb.empty() || r.variance.rgb.size() == n * 3, "variance size");
    check(r.samples.empty() || r.samples.size() == n, "samples size");
  } catch (const lucent::Error&) {
  }
  return 0;
}
