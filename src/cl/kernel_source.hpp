#pragma once
#include <string>

namespace lucent::detail {

struct EmbeddedKernelFile {
  const char* path;  ///< relative to kernels/, e.g. "bvh/traverse.cl"
  const char* content;
};
extern const EmbeddedKernelFile kEmbeddedKernelFiles[];
extern const int kEmbeddedKernelFileCount;

/// The text of kernels/<path>: generated/... files from the registries (whatever the source), else
/// from `kernel_dir` when it is not empty (kernel development without rebuilding; the CLI's
/// default is LUCENT_KERNEL_DIR), else from the copy embedded at build time. Throws lucent::Error.
std::string read_kernel_file(const std::string& path, const std::string& kernel_dir = "");

/// kernels/<path> with every `#include "x"` replaced by the file's text (each file once), and
/// `#line N "kernels/<file>"` markers so compiler messages point at the .cl sources.
std::string assemble_kernel_source(const std::string& path, const std::string& kernel_dir = "");

}  // namespace lucent::detail
