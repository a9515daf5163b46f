#pragma once
// Image files as they enter lucent (textures, environment maps, images given to compare and
// converge): the format from the file's magic bytes, the size its header claims, checked against
// a pixel limit and against what the file's length can hold, and the decoders that take the
// file's bytes. Nothing is allocated for pixels before the header has passed the checks.
#include <tinyexr.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/file_io.hpp"
#include "lucent/image.hpp"
#include "lucent/render.hpp"

namespace lucent::image_detail {

enum class Format { Png, Jpeg, Bmp, Tga, Hdr, Pfm, Exr };

const char* format_name(Format f);

/// PNG, JPEG, BMP and TGA hold display values (tone-mapped, encoded, clipped: 8 or 16 bits);
/// OpenEXR, PFM and Radiance HDR linear radiance.
inline bool is_display_format(Format f) {
  return f != Format::Exr && f != Format::Pfm && f != Format::Hdr;
}

#ifndef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
/// Upper bound on width * height of any image lucent reads (the largest film, 16384 x 16384).
constexpr std::uint64_t kMaxImagePixels = 16384ull * 16384ull;
/// Upper bound on a texture's or environment map's width * height (8192 x 8192, or 16384 x 4096:
/// 1 GiB as linear RGBA float, the form textures take).
constexpr std::uint64_t kMaxTexturePixels = 8192ull * 8192ull;
#else
// fuzzing: valid images this large take seconds to decode and would only slow the search down
constexpr std::uint64_t kMaxImagePixels = 1ull << 22;
constexpr std::uint64_t kMaxTexturePixels = 1ull << 22;
#endif
/// Upper bound on an image file's size.
constexpr std::uint64_t kMaxImageFileBytes = 4ull << 30;
/// Upper bound on a part file's size (lucent/parts.hpp): 19 channels of 4 bytes per pixel of the
/// largest film, and room for headers and compression's overhead. A 16384 x 16384 part holds
/// about 20 GB; under kMaxImageFileBytes, parts of films above about 9000 x 9000 were written but
/// could not be read back.
constexpr std::uint64_t kMaxPartFileBytes = 80ull * kMaxImagePixels + (64ull << 20);

struct Probe {
  Format format = Format::Png;
  int width = 0;
  int height = 0;
  bool sixteen_bit = false;  ///< a 16-bit PNG
  int channels = 0;          ///< an OpenEXR's channels
  int compression = -1;      ///< an OpenEXR's compression (TINYEXR_COMPRESSIONTYPE_*)
  /// The pixels decoding holds at once, where not width * height: an OpenEXR whose data window
  /// (the pixels stored) is not its display window (the image, width x height), both.
  std::uint64_t decode_pixels = 0;
  /// An OpenEXR with lucent's checksum attribute (a part file: a checkpoint, a --samples part),
  /// whose image read_image takes from its checksummed sums.
  bool lucent_part = false;
  /// A palette image (a PNG of colour type 3, a BMP of 8 bits or fewer a pixel) whose palette
  /// has fewer entries than its indices can name. stb_image reads an index past the palette from
  /// memory it never set (a texture, and the render, changed from run to run): decode_image pads
  /// the palette with a colour none of its entries has, and refuses a pixel of that colour.
  struct ShortPalette {
    std::uint64_t entries = 0;       ///< the palette's entries; 0: not a short palette
    std::uint64_t names = 0;         ///< the entries the indices can name (2^bits, at most 256)
    std::uint64_t entry_bytes = 0;   ///< 3 (PNG: R, G, B; an OS/2 BMP: B, G, R) or 4 (BMP)
    std::uint64_t start = 0;         ///< the palette's first entry in the file
    std::uint64_t length_field = 0;  ///< PNG: the PLTE chunk's length; BMP: the pixels' offset
  };
  ShortPalette short_palette = {};
};

/// Identifies the format of `data` (PNG, JPEG, BMP, TGA, Radiance HDR, PFM, OpenEXR; anything
/// else is refused), reads the size its header claims and checks it: at least one pixel, at most
/// `max_pixels`, and no more than the file's length can hold (uncompressed formats need every
/// byte; run-length streams are walked without decoding; deflate and JPEG streams have a
/// bounded compression ratio). Throws lucent::Error("<path>: ...") on the first problem.
Probe probe_image(const unsigned char* data, std::size_t size, const std::string& path,
                  std::uint64_t max_pixels);

/// Where a PFM file's pixels are.
struct PfmLayout {
  std::uint64_t data_offset = 0;
  int channels = 3;
  bool big_endian = false;
};

/// probe_image for a PFM file, with the layout of its pixels.
Probe probe_pfm(const unsigned char* data, std::size_t size, const std::string& path,
                std::uint64_t max_pixels, PfmLayout& layout);

/// Refuses to decode the `thing` ("image", "part") of `path` that `p` describes when its file
/// (`file_bytes`) and `bytes_per_pixel` for each of its pixels exceed the host's memory limit
/// (sys::host_memory_allowed): past it the process would be killed without a word.
void check_decode_memory(const std::string& path, const char* thing, const Probe& p,
                         std::uint64_t bytes_per_pixel, std::uint64_t file_bytes);

/// probe_image for an OpenEXR file (checks its PIZ chunks too), with its header parsed by
/// tinyexr into `header` (the caller frees it with FreeEXRHeader).
Probe probe_exr(const unsigned char* data, std::size_t size, const std::string& path,
                std::uint64_t max_pixels, EXRHeader& header);

/// An OpenEXR window's width and height, in 64 bits (its corners are int32: a width can pass
/// 2^31, and an inverted window gives 0 or less).
struct ExrWindowSize {
  std::int64_t width = 0, height = 0;
};
inline ExrWindowSize exr_window_size(const EXRBox2i& b) {
  return {std::int64_t(b.max_x) - b.min_x + 1, std::int64_t(b.max_y) - b.min_y + 1};
}
/// Whether a file's data window (the pixels stored) is its display window (the image).
inline bool exr_windows_equal(const EXRBox2i& a, const EXRBox2i& b) {
  return a.min_x == b.min_x && a.min_y == b.min_y && a.max_x == b.max_x && a.max_y == b.max_y;
}

/// tinyexr's error text on one line (it ends its messages with newlines); frees `err`.
std::string exr_message(const char* err);

/// A decoded image with four channels (RGBA) or three (RGB); linear floats, row 0 at the top.
/// 8-bit and 16-bit data are decoded from sRGB to linear (alpha stays linear).
struct Decoded {
  Format format = Format::Png;
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;
};

/// Decodes image bytes that probe_image accepted (it is called again first).
Decoded decode_image(const unsigned char* data, std::size_t size, const std::string& path,
                     int channels, std::uint64_t max_pixels);

/// An OpenEXR file's channels, each converted to float (HALF widened, UINT converted).
struct ExrChannels {
  int width = 0, height = 0;
  std::vector<std::string> names;
  std::vector<std::vector<float>> planes;  ///< one per name, width * height, row 0 at the top
  /// The exact values of UINT channels (empty for the others), as `planes`
  std::vector<std::vector<std::uint32_t>> uint_planes;
  std::map<std::string, std::string> attributes;  ///< the header's attributes of type string
  int find(const char* name) const;               ///< index of a channel, or -1
};

/// The header's custom attributes of type string, by name.
std::map<std::string, std::string> exr_string_attributes(const EXRHeader& header);

/// A string attribute's whole unsigned decimal number of at most `max`; throws lucent::Error
/// "<path>: attribute <what>: invalid number '<s>'".
std::uint64_t parse_attribute_u64(const std::string& path, const std::string& what,
                                  const std::string& s,
                                  std::uint64_t max = std::numeric_limits<std::uint64_t>::max());

/// Reads every channel of a scanline or tiled single-part OpenEXR held in memory.
ExrChannels read_exr_channels(const unsigned char* data, std::size_t size, const std::string& path,
                              std::uint64_t max_pixels);

/// How image files are read: regular files of at most kMaxImageFileBytes.
io::ReadSpec image_read_spec(const char* what = "image");
/// How part files are read: regular files of at most kMaxPartFileBytes.
io::ReadSpec part_read_spec();
/// The memory an OpenEXR of lucent's (read_render, read_render_part) is decoded in, per pixel,
/// beside the file itself: tinyexr's planes, their float and integer copies, and the result's
/// images or sums, by the probe's channels and compression. Measured between 960x540 and
/// 1920x1080 (tinyexr 1.0.1): a render's 7 ZIP channels 67 bytes a pixel; a part's 19 channels
/// 246 with ZIP or PIZ, 282 uncompressed. Counted: 131, 287 and 325, and at least 128. (A count
/// of 128 for every OpenEXR let a part read by `lucent compare` take twice it.)
std::uint64_t exr_decode_bytes_per_pixel(const Probe& p);

/// Encodes `image` as OpenEXR in memory; throws lucent::Error("<path>: cannot encode EXR: ...").
std::string save_exr_to_memory(const std::string& path, const EXRImage& image,
                               const EXRHeader& header);

/// Encodes `image` as OpenEXR and writes it to `path` (io::write_file_atomic, from tinyexr's own
/// buffer: no copy of the file); throws lucent::Error("<path>: cannot encode EXR: ...").
void write_exr(const std::string& path, const EXRImage& image, const EXRHeader& header);

/// The host memory write_exr's encoder takes at most for `raw` bytes of pixels (its chunks, then
/// the file in one block; ZIP adds a few bytes per block to data it cannot compress).
std::uint64_t exr_encoder_bytes(std::uint64_t raw);

/// The host memory lucent::write_image allocates for a width x height image written to `path`
/// (by its extension), beside the image itself, at most: the encoded file and the encoder's own
/// buffers (PNG through stb_image_write, EXR's planes and tinyexr).
std::uint64_t image_write_bytes(const std::string& path, int width, int height);

/// What a render EXR may carry beyond write_render_exr's layers: UINT channels (name, width *
/// height values) and string attributes (name, value).
struct ExrExtras {
  std::vector<std::pair<std::string, const std::uint32_t*>> uint_channels;
  std::vector<std::pair<std::string, std::string>> attributes;
  bool piz = false;  ///< PIZ compression instead of ZIP (PartCompression)
};

/// The attribute lucent.light_mean_var of RenderResult::light_mean_variance: its paths and its
/// pixels (R G B each), six numbers in decimal (docs/compare.md), and back: throws lucent::Error
/// "<path>: attribute lucent.light_mean_var: ..." unless the text is six finite numbers >= 0.
std::string light_mean_var_attribute(const LightMeanVariance& v);
LightMeanVariance parse_light_mean_var(const std::string& path, const std::string& text);

/// write_render_exr() with extra channels and attributes.
void write_render_exr(const std::string& path, const RenderResult& r, const ExrExtras& extras);

/// A render's images as planes (width * height values each), for write_render_planes: the mean
/// (R, G, B) and, where variance and samples are all set, the statistics (var.R, var.G, var.B,
/// n). Pointers only: the caller's arrays are written without a copy.
struct RenderPlanes {
  int width = 0, height = 0;
  const float* mean[3] = {nullptr, nullptr, nullptr};
  const float* variance[3] = {nullptr, nullptr, nullptr};
  const std::uint32_t* samples = nullptr;
};

/// An EXR of `mean` (R, G, B) and, with `variance` and `samples` (width * height counts), the
/// statistics' layers, as write_render_exr writes them (lucent::write_image's EXR is the mean
/// alone); the images must hold width * height RGB pixels.
void write_image_exr(const std::string& path, const Image& mean, const Image* variance,
                     const std::uint32_t* samples, const ExrExtras& extras);

/// write_render_exr() of planes the caller holds.
void write_render_planes(const std::string& path, const RenderPlanes& r, const ExrExtras& extras);

/// The host memory write_render_exr takes beside its RenderResult at width x height: its planes
/// and the encoder (with the statistics' layers when `stats`, and `extra_uint_channels` more).
std::uint64_t render_exr_write_bytes(int width, int height, bool stats,
                                     int extra_uint_channels = 0);

/// read_render() on a file's bytes: an EXR with lucent's layers (mean, var.R/G/B, n), or any
/// image decode_image reads (variance and samples left empty).
RenderResult read_render_memory(const unsigned char* data, std::size_t size,
                                const std::string& path);

/// lucent::read_render(), which also says the file's format (decided from its bytes, which are
/// read once) when `format` is not null.
RenderResult read_render(const std::string& path, Format* format);

/// sRGB-encoded value in [0, 1] to linear.
double srgb_to_linear(double c);
/// An 8-bit sRGB value to linear (a table of srgb_to_linear).
float srgb8_to_linear(std::uint8_t v);

}  // namespace lucent::image_detail
