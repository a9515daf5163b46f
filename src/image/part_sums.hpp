#pragma once
// A part file's sums in its OpenEXR channels (render/parts.cpp writes them): each double as two
// UINT channels, "<sum|sumsq>.<R|G|B>.hi" and ".lo", the counts in the UINT channel "n", and a
// checksum of them all in the attribute lucent.checksum. In the image layer, so that read_render
// reads a part file from the sums the checksum covers (its display channels, R, G, B and var.*,
// are covered by none), also in the fuzz targets, which build no render layer.
#include <cstdint>
#include <string>
#include <vector>

#include "image/image_probe.hpp"
#include "lucent/image.hpp"

namespace lucent::image_detail {

/// "sum.R.hi", "sumsq.B.lo", ...: plane 0 the sums, 1 the sums of squares; channel c of R, G, B.
std::string part_channel_name(int plane, int c, bool high);

/// The check of a part's samples, its attribute lucent.checksum: the bits of every sum, sum of
/// squares and count, chained through a multiply and a shift. A PIZ chunk (a checkpoint's) has no
/// check of its own, unlike ZIP's Adler-32: a damaged one that still decodes gave other sums.
std::uint64_t part_sums_checksum(const std::vector<double>& sum, const std::vector<double>& sumsq,
                                 const std::vector<std::uint32_t>& count);

/// `v` as 16 lower-case hexadecimal digits (the checksum's and the scene hash's text).
std::string hex64(std::uint64_t v);

struct PartSums {
  std::vector<double> sum, sumsq;    ///< 3 per pixel, row 0 at the top
  std::vector<std::uint32_t> count;  ///< per pixel
};

/// Whether n samples of sums `sum` and `sumsq` have a mean and a per-sample variance that a float
/// holds. A render's pixels always do (the kernel drops a sample whose square overflows a float
/// as non-finite); a crafted part's, or a merge of such parts, may not.
bool sums_fit_float(double sum, double sumsq, double n);

/// Throws lucent::Error "<name>: pixel X, Y: its mean or sample variance is beyond a float's
/// range" for the first pixel-channel (of those the three vectors all hold) whose sums do not
/// fit (sums_fit_float); rows of `width` pixels.
void check_sums_fit_float(const std::string& name, int width, const std::vector<double>& sum,
                          const std::vector<double>& sumsq,
                          const std::vector<std::uint32_t>& count);

/// A part's image from its sums: each pixel's mean and the variance of one of its samples, per
/// channel, in floats (what part_result gives, read_render reads from a part file, and
/// write_render_part's display channels hold). Throws lucent::Error naming `name` and the pixel
/// where a mean or variance is beyond a float's range (it would be written as infinite).
void part_image(const std::string& name, int width, int height, const std::vector<double>& sum,
                const std::vector<double>& sumsq, const std::vector<std::uint32_t>& count,
                Image& mean, Image& variance);

/// The sums, sums of squares and counts of the part file `path` from its decoded channels: each
/// sum finite, each sum of squares >= 0, all of them matching lucent.checksum where the file has
/// one (part files written before 30 Nov 2026 have none), and each pixel's mean and variance
/// within a float's range (sums_fit_float). Throws lucent::Error naming `path`.
PartSums part_sums_from_channels(const ExrChannels& exr, const std::string& path);

}  // namespace lucent::image_detail
