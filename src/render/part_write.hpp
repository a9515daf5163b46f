#pragma once
// The part file's writer without write_render_part's checks, for tests that make damaged part
// files to see what reading and merging say of them.
#include <string>

#include "lucent/parts.hpp"

namespace lucent::parts_detail {

/// Writes `part` as it is, even a header, counts or sums that read_render_part refuses.
/// write_render_part checks them first, then calls this.
void write_part_unchecked(const std::string& path, const RenderPart& part,
                          PartCompression compression = PartCompression::zip);

}  // namespace lucent::parts_detail
