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
/// from LUCENT_KERNEL_DIR when that is set (kernel development
/// without rebuilding), else from the copy embedded at build time. Throws lucent::Error.
std::string read_kernel_file(const std::string& path);

/// kernels/<path> with every `#include "x"` replaced by the file's text (each file once), and
/// `#line N "kernels/<file>"` markers so compiler messages point at the .cl sources.
std::string assemble_kernel_source(const std::string& path);

/// Where kernel sources come from: "embedded" or the LUCENT_KERNEL_DIR directory.
std::string kernel_source_origin();

}  // namespace lucent::detail
