#pragma once
// A part file's sums from its decoded OpenEXR channels: read_render_part's decoding, shared with
// read_render, which reads a part file's image from its sums (checked by the file's checksum)
// rather than from its display channels (R, G, B, var.*, which no checksum covers).
#include <string>

#include "image/image_probe.hpp"
#include "lucent/parts.hpp"

namespace lucent::render_detail {

/// The part in `exr` (the channels and attributes of the part file `path`): its header, sums,
/// sums of squares and counts, each checked (the checksum, the counts against the ranges).
/// Throws lucent::Error naming `path`.
RenderPart part_from_channels(const image_detail::ExrChannels& exr, const std::string& path);

}  // namespace lucent::render_detail
