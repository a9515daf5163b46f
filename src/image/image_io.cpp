// Image output and input. Outputs are encoded in memory (PNG through stb_image_write, PFM by
// hand, EXR through tinyexr) and written through a temporary file renamed into place; inputs are
// read with a bound and their headers checked before decoding (image/image_probe.cpp).
#include <stb/stb_image_write.h>
#include <tinyexr.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/file_io.hpp"
#include "core/host_memory.hpp"
#include "core/text.hpp"
#include "image/image_probe.hpp"
#include "lucent/error.hpp"
#include "lucent/image.hpp"

namespace lucent {

namespace {

std::string extension(const std::string& path) {
  auto dot = path.find_last_of('.');
  auto slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

/// A tone map of v >= 0 (infinity included: an exposure of 1e30 stops makes one, and inf / inf
/// was NaN, written as black where the curve tends to white).
double tonemap(double v, ToneMap t) {
  switch (t) {
    case ToneMap::Reinhard:
      return std::isinf(v) ? 1.0 : v / (1.0 + v);
    case ToneMap::Aces: {
      // Narkowicz 2015 fit of the ACES filmic curve; beyond 1e100 its products overflow, and it
      // is a / c there to double precision
      const double a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
      if (v > 1e100) return a / c;
      return (v * (a * v + b)) / (v * (c * v + d) + e);
    }
    default:
      return v;
  }
}

// PFM: a text header, then rows bottom to top, little-endian floats (negative scale)
std::string encode_pfm(const Image& img) {
  std::string out =
      "PF\n" + std::to_string(img.width) + " " + std::to_string(img.height) + "\n-1.0\n";
  const size_t row = sizeof(float) * 3 * static_cast<size_t>(img.width);
  out.reserve(out.size() + row * static_cast<size_t>(img.height));
  for (int y = img.height - 1; y >= 0; --y)
    out.append(reinterpret_cast<const char*>(img.pixel(0, y)), row);
  return out;
}

void append_bytes(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                             static_cast<size_t>(size));
}

/// Whether stb_image_write flips the rows it writes: its setting is the process's (the
/// application's too: the library is shared), which lucent neither depends on nor changes (an
/// application's stbi_flip_vertically_on_write(1), common in OpenGL screenshot code, wrote
/// lucent's PNGs upside down).
bool stb_flips_on_write() {
  const unsigned char px[6] = {255, 255, 255, 0, 0, 0};  // white above black
  std::string bmp;
  stbi_write_bmp_to_func(append_bytes, &bmp, 1, 2, 3, px);
  // a BMP's rows are stored bottom first (its pixels from byte 54): black first, unless flipped
  return bmp.size() > 54 && static_cast<unsigned char>(bmp[54]) == 255;
}

/// `v` as 4 bytes, most significant first (PNG's integers).
std::string be32(std::uint32_t v) {
  return std::string{char(v >> 24), char(v >> 16 & 0xFF), char(v >> 8 & 0xFF), char(v & 0xFF)};
}

/// A PNG chunk: its length, tag, data and CRC-32 (ISO 3309, as the PNG specification gives it).
std::string png_chunk(const char* tag, const std::string& data) {
  const std::string body = std::string(tag, 4) + data;
  std::uint32_t crc = 0xFFFFFFFFu;
  for (unsigned char b : body) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return be32(static_cast<std::uint32_t>(data.size())) + body + be32(~crc);
}

/// The chunks that say how the 8-bit values encode light, after IHDR: sRGB (and the gAMA of 1/2.2
/// the specification asks beside it for older decoders), or gAMA 1/gamma for the gamma transfer
/// and 1 for linear. Without them a viewer takes any PNG for sRGB, and showed a linear or
/// gamma-1.8 image too dark or too light with nothing in the file to say otherwise.
std::string png_colour_chunks(const DisplaySettings& display) {
  const auto gama = [](double file_gamma) {
    const auto v = static_cast<std::uint32_t>(std::lround(std::clamp(file_gamma, 1e-5, 4e4) * 1e5));
    return png_chunk("gAMA", be32(v));
  };
  switch (display.transfer) {
    case Transfer::Srgb:
      return png_chunk("sRGB", std::string(1, '\0')) + gama(1 / 2.2);
    case Transfer::Gamma:
      return gama(1 / display.gamma);
    case Transfer::Linear:
      break;
  }
  return gama(1.0);
}

/// Refuses display settings a scene's film may not have, as `<where>: ...`: a gamma of 0 wrote
/// a black PNG, an unknown transfer a linear one (and encode_display took a gamma of NaN as 0
/// and a transfer of 77 as linear where write_image refused them).
void check_display(const std::string& where, const DisplaySettings& display) {
  if (!(display.gamma > 0) || !std::isfinite(display.gamma) || !std::isfinite(display.exposure))
    throw Error(where + ": the display gamma must be finite and > 0, the exposure finite (gamma " +
                io::shortest_real(display.gamma) + ", exposure " +
                io::shortest_real(display.exposure) + ")");
  const auto transfer = static_cast<int>(display.transfer);
  const auto tonemap = static_cast<int>(display.tonemap);
  if (transfer < 0 || transfer > static_cast<int>(Transfer::Linear) || tonemap < 0 ||
      tonemap > static_cast<int>(ToneMap::Aces))
    throw Error(where + ": unknown display transfer or tone map (" + std::to_string(transfer) +
                ", " + std::to_string(tonemap) + ")");
}

/// encode_display, of settings already checked (check_display).
unsigned char encode_checked(double v, const DisplaySettings& d) {
  // NaN/Inf never reach a render's film, but lucent::write_image and Python's write_image take
  // any array: NaN has no brightness (black); +inf is brighter than any finite value and is
  // encoded as one (it was black, next to a white 3e38), whatever the exposure (+inf times a
  // scale that underflows to 0 was NaN)
  if (std::isnan(v)) v = 0;
  if (std::isinf(v) && v > 0) v = std::numeric_limits<double>::max();
  // (0 times an infinite scale is NaN: black stays black)
  v = v > 0 ? v * std::exp2(d.exposure) : 0.0;
  if (std::isnan(v)) v = 0;
  v = tonemap(v, d.tonemap);
  v = std::clamp(v, 0.0, 1.0);
  switch (d.transfer) {
    case Transfer::Srgb:
      v = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
      break;
    case Transfer::Gamma:
      v = std::pow(v, 1.0 / d.gamma);
      break;
    case Transfer::Linear:
      break;
  }
  return static_cast<unsigned char>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

std::string encode_png(const std::string& path, const Image& img, const DisplaySettings& display) {
  std::vector<unsigned char> bytes(img.rgb.size());
  const size_t row = size_t(img.width) * 3;
  const bool flipped = stb_flips_on_write();  // (rows given bottom first: flipped back)
  for (size_t i = 0; i < bytes.size(); ++i) {
    const size_t y = i / row, from = flipped ? (size_t(img.height) - 1 - y) * row + i % row : i;
    bytes[i] = encode_checked(img.rgb[from], display);
  }
  std::string out;
  auto append = append_bytes;
  if (!stbi_write_png_to_func(append, &out, img.width, img.height, 3, bytes.data(), img.width * 3))
    throw Error(path + ": cannot encode PNG");
  // (after the signature and IHDR, 8 + 25 bytes: before the image data, as the chunks must be)
  if (out.size() < 33 || out.compare(12, 4, "IHDR") != 0) throw Error(path + ": cannot encode PNG");
  out.insert(33, png_colour_chunks(display));
  return out;
}

}  // namespace

unsigned char encode_display(double v, const DisplaySettings& d) {
  check_display("encode_display", d);
  return encode_checked(v, d);
}

namespace image_detail {

std::uint64_t image_write_bytes(const std::string& path, int width, int height) {
  const std::uint64_t npix = std::uint64_t(std::max(width, 0)) * std::uint64_t(std::max(height, 0));
  const std::string ext = extension(path);
  // EXR: three float planes and the encoder; PFM: the file; PNG: the 8-bit pixels, and
  // stb_image_write's filtered rows, its deflate buffer (grown by doubling, so up to twice the
  // pixels), the file and this side's copy of it
  // (saturated counts, sys::bytes_mul: a film's pixels reach 2^62)
  const std::uint64_t floats = sys::bytes_mul(npix, 3 * sizeof(float));
  if (ext == "exr") return sys::bytes_add(floats, exr_encoder_bytes(floats));
  if (ext == "pfm") return sys::bytes_add(floats, 64);
  return sys::bytes_add(sys::bytes_mul(npix, 3 * 6), std::uint64_t(1) << 16);
}

}  // namespace image_detail

void write_image(const std::string& path, const Image& img, const DisplaySettings& display) {
  if (img.width <= 0 || img.height <= 0 ||
      img.rgb.size() != static_cast<size_t>(img.width) * img.height * 3)
    throw Error(path + ": refusing to write an empty or inconsistent image");
  check_display(path, display);  // as a scene's film
  std::string ext = extension(path);
  if (ext == "pfm")
    io::write_file_atomic(path, encode_pfm(img));
  else if (ext == "exr")
    image_detail::write_image_exr(path, img, nullptr, nullptr, {});  // the mean layers alone
  else if (ext == "png")
    io::write_file_atomic(path, encode_png(path, img, display));
  else
    io::unknown_output_format(path, ext.empty() ? "" : "." + ext, ".png, .pfm or .exr");
}

Image read_image(const std::string& path) {
  const std::string bytes = io::read_file(path, image_detail::image_read_spec());
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  // within the host's memory, as read_render's: a 341-byte OpenEXR of a 1x1 data window in a
  // 16384x16384 display window decodes to 3 GB
  const image_detail::Probe p =
      image_detail::probe_image(data, bytes.size(), path, image_detail::kMaxImagePixels);
  image_detail::check_decode_memory(
      path, "image", p,
      p.format == image_detail::Format::Exr ? image_detail::exr_decode_bytes_per_pixel(p) : 32,
      bytes.size());
  // a part file: its image from its sums, which its checksum covers, as read_render's (its
  // display channels are not covered: a damaged PIZ chunk of a checkpoint read as a changed
  // mean without a word)
  if (p.lucent_part) return image_detail::read_render_memory(data, bytes.size(), path).mean;
  image_detail::Decoded d =
      image_detail::decode_image(data, bytes.size(), path, 3, image_detail::kMaxImagePixels);
  return Image{d.width, d.height, std::move(d.pixels)};
}

}  // namespace lucent
