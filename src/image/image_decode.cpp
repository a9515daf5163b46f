// Image decoding, after the header checks of image_probe.cpp: PNG, JPEG, BMP, TGA and Radiance
// HDR through stb_image, PFM by hand, OpenEXR through tinyexr (every channel, widened to float);
// and EXR encoding in memory.
#include <stb/stb_image.h>
#include <tinyexr.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <type_traits>

#include "core/file_io.hpp"
#include "core/host_memory.hpp"
#include "image/image_probe.hpp"
#include "lucent/error.hpp"

namespace lucent::image_detail {

namespace {

// Throws lucent::Error("<path>: <what>").
struct Fail {
  const std::string& path;
  [[noreturn]] void operator()(const std::string& what) const { throw Error(path + ": " + what); }
};

std::string stb_reason() {
  const char* r = stbi_failure_reason();
  return r ? r : "unknown error";
}

struct StbFree {
  void operator()(void* p) const { stbi_image_free(p); }
};

/// A copy of the file of `p`, a short palette's (Probe::ShortPalette), with its palette padded to
/// every entry its indices can name, in a colour (`*colour`, RGB) that none of its entries has.
std::vector<unsigned char> pad_palette(const unsigned char* data, std::size_t size, const Probe& p,
                                       std::array<unsigned char, 3>* colour) {
  const Probe::ShortPalette& pal = p.short_palette;
  const bool bgr = p.format == Format::Bmp;
  // 257 candidates (k mod 256, k / 256, 0): at most 256 are taken
  std::array<unsigned char, 3> pick{0, 0, 0};
  for (unsigned k = 0; k < 257; ++k) {
    const unsigned char r = static_cast<unsigned char>(k & 255),
                        g = static_cast<unsigned char>(k >> 8);
    bool taken = false;
    for (std::uint64_t e = 0; e < pal.entries && !taken; ++e) {
      const unsigned char* c = data + pal.start + e * pal.entry_bytes;
      taken = c[bgr ? 2 : 0] == r && c[1] == g && c[bgr ? 0 : 2] == 0;
    }
    if (!taken) {
      pick = {r, g, 0};
      break;
    }
  }
  *colour = pick;
  const std::uint64_t at = pal.start + pal.entries * pal.entry_bytes;
  const std::uint64_t added = (pal.names - pal.entries) * pal.entry_bytes;
  std::vector<unsigned char> out;
  out.reserve(size + added);
  out.insert(out.end(), data, data + at);
  for (std::uint64_t e = pal.entries; e < pal.names; ++e) {
    const unsigned char entry[4] = {bgr ? pick[2] : pick[0], pick[1], bgr ? pick[0] : pick[2], 0};
    out.insert(out.end(), entry, entry + pal.entry_bytes);
  }
  out.insert(out.end(), data + at, data + size);
  // the PLTE chunk's length (its CRC is left as it was: stb_image skips CRCs), or the BMP's
  // offset of its pixels
  unsigned char* field = out.data() + pal.length_field;
  if (bgr) {
    std::uint32_t v = std::uint32_t(field[0]) | std::uint32_t(field[1]) << 8 |
                      std::uint32_t(field[2]) << 16 | std::uint32_t(field[3]) << 24;
    v += static_cast<std::uint32_t>(added);
    for (int i = 0; i < 4; ++i) field[i] = static_cast<unsigned char>(v >> (8 * i));
  } else {
    const std::uint32_t v = static_cast<std::uint32_t>(pal.names * 3);
    for (int i = 0; i < 4; ++i) field[i] = static_cast<unsigned char>(v >> (8 * (3 - i)));
  }
  return out;
}

/// Whether stb_image flips the rows it decodes (the process's setting, or this thread's).
bool stb_flips_on_load() {
  // a grey PNG of 1x2 pixels, white above black
  static const unsigned char kProbe[] = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
      0x44, 0x52, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x02, 0x08, 0x00, 0x00, 0x00,
      0x00, 0xbc, 0xea, 0xe9, 0xfb, 0x00, 0x00, 0x00, 0x0c, 0x49, 0x44, 0x41, 0x54, 0x78,
      0xda, 0x63, 0xf8, 0xcf, 0xc0, 0x00, 0x00, 0x03, 0x01, 0x01, 0x00, 0xf7, 0x03, 0x41,
      0x43, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  int w = 0, h = 0, n = 0;
  std::unique_ptr<stbi_uc, StbFree> px(
      stbi_load_from_memory(kProbe, static_cast<int>(sizeof kProbe), &w, &h, &n, 1));
  return px && w == 1 && h == 2 && px.get()[0] == 0;
}

}  // namespace

io::ReadSpec image_read_spec(const char* what) {
  io::ReadSpec spec;
  spec.what = what;
  spec.max_bytes = kMaxImageFileBytes;
  return spec;
}

std::uint64_t exr_decode_bytes_per_pixel(const Probe& p) {
  const std::uint64_t channels = std::uint64_t(std::max(p.channels, 0));
  // at least the 128 bytes counted for any OpenEXR before (another tool's, decoded to RGBA)
  const bool uncompressed = p.compression == TINYEXR_COMPRESSIONTYPE_NONE;
  return std::max<std::uint64_t>(128, (uncompressed ? 15 : 13) * channels + 40);
}

io::ReadSpec part_read_spec() {
  io::ReadSpec spec;
  spec.what = "part file";
  spec.max_bytes = kMaxPartFileBytes;
  return spec;
}

std::uint64_t exr_encoder_bytes(std::uint64_t raw) {
  return sys::bytes_add(sys::bytes_mul(2, sys::bytes_add(raw, raw / 64)), std::uint64_t(1) << 20);
}

namespace {

struct FreeDeleter {
  void operator()(unsigned char* p) const { std::free(p); }
};
using ExrBlock = std::unique_ptr<unsigned char, FreeDeleter>;

/// tinyexr's encoded file, in its own block of `*size` bytes.
ExrBlock encode_exr(const std::string& path, const EXRImage& image, const EXRHeader& header,
                    std::size_t* size) {
  // tinyexr does not check its allocations: short of memory (ulimit -v), its encoder wrote
  // through a null pointer, and a part file's render ended in SIGSEGV after it had rendered (the
  // resources review). Its peak is about twice the encoded file (its chunks, then the file in one
  // block); the encoded file is at most the raw pixels plus ZIP's few bytes per block. That much
  // memory is asked for first and given back: where it cannot be had, a clear error instead of
  // the crash.
  std::uint64_t raw = 0;
  for (int c = 0; c < header.num_channels; ++c)
    raw += std::uint64_t(header.pixel_types[c] == TINYEXR_PIXELTYPE_HALF ? 2 : 4) *
           std::uint64_t(image.width) * std::uint64_t(image.height);
  const std::uint64_t need = exr_encoder_bytes(raw);
  if (void* probe = need <= SIZE_MAX ? std::malloc(static_cast<std::size_t>(need)) : nullptr) {
    std::free(probe);
  } else {
    char mib[32];
    std::snprintf(mib, sizeof mib, "%.0f", double(need) / (1 << 20));
    throw Error(path + ": cannot encode EXR: not enough memory for its encoder (about " + mib +
                " MiB; the address-space limit, ulimit -v, or the machine's memory)");
  }
  unsigned char* memory = nullptr;
  const char* err = nullptr;
  *size = SaveEXRImageToMemory(&image, &header, &memory, &err);
  ExrBlock block(memory);
  if (*size == 0 || !block) throw Error(path + ": cannot encode EXR: " + exr_message(err));
  return block;
}

}  // namespace

std::string save_exr_to_memory(const std::string& path, const EXRImage& image,
                               const EXRHeader& header) {
  std::size_t size = 0;
  ExrBlock block = encode_exr(path, image, header, &size);
  return std::string(reinterpret_cast<const char*>(block.get()), size);
}

void write_exr(const std::string& path, const EXRImage& image, const EXRHeader& header) {
  // written from tinyexr's block: a copy of the file was a third of the encoder's peak
  std::size_t size = 0;
  ExrBlock block = encode_exr(path, image, header, &size);
  io::write_file_atomic(path, block.get(), size);
}

double srgb_to_linear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

float srgb8_to_linear(std::uint8_t v) {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = static_cast<float>(srgb_to_linear(i / 255.0));
    return t;
  }();
  return table[v];
}

int ExrChannels::find(const char* name) const {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

std::map<std::string, std::string> exr_string_attributes(const EXRHeader& header) {
  std::map<std::string, std::string> out;
  for (int a = 0; a < header.num_custom_attributes; ++a) {
    const EXRAttribute& attr = header.custom_attributes[a];
    if (std::strcmp(attr.type, "string") == 0 && attr.size >= 0 && attr.value)
      out[attr.name] =
          std::string(reinterpret_cast<const char*>(attr.value), static_cast<size_t>(attr.size));
  }
  return out;
}

ExrChannels read_exr_channels(const unsigned char* data, std::size_t size, const std::string& path,
                              std::uint64_t max_pixels) {
  const Fail fail{path};
  EXRHeader header;
  probe_exr(data, size, path, max_pixels, header);
  // lineOrder only says in which order the chunks are stored, and each chunk names its rows or
  // tile; tinyexr 1.0.1 flips the rows of every chunk of a DECREASING_Y file (its issue 213,
  // fixed upstream by always decoding as INCREASING_Y): an image upside down, or tiles flipped
  // with rows left uninitialised
  header.line_order = 0;
  for (int c = 0; c < header.num_channels; ++c)
    if (header.pixel_types[c] == TINYEXR_PIXELTYPE_HALF)
      header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
  // defence in depth: tinyexr's decoders have read a few kilobytes past a chunk; whatever they
  // still read past the file's end is zeros, never another object's memory
  std::vector<unsigned char> padded(size + (64u << 10), 0);
  std::memcpy(padded.data(), data, size);
  data = padded.data();
  EXRImage image;
  InitEXRImage(&image);
  // tinyexr frees a half-decoded scanline image on failure with FreeEXRImage, which frees only
  // num_channels channel buffers: still 0 there unless set beforehand (found by fuzzing)
  image.num_channels = header.num_channels;
  const char* err = nullptr;
  if (LoadEXRImageFromMemory(&image, &header, data, size, &err) != TINYEXR_SUCCESS) {
    FreeEXRHeader(&header);
    fail("cannot read OpenEXR pixels: " + exr_message(err));
  }
  ExrChannels out;
  out.width = image.width;
  out.height = image.height;
  const size_t n = static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
  for (int c = 0; c < header.num_channels; ++c) {
    out.names.push_back(header.channels[c].name);
    out.planes.emplace_back(n, 0.0f);
    out.uint_planes.emplace_back(header.requested_pixel_types[c] == TINYEXR_PIXELTYPE_UINT ? n : 0,
                                 0u);
  }
  out.attributes = exr_string_attributes(header);
  auto copy = [&](int c, const unsigned char* src, size_t from, size_t to) {
    if (header.requested_pixel_types[c] == TINYEXR_PIXELTYPE_UINT) {
      const unsigned int v = reinterpret_cast<const unsigned int*>(src)[from];
      out.uint_planes[c][to] = v;
      out.planes[c][to] = static_cast<float>(v);
    } else {
      out.planes[c][to] = reinterpret_cast<const float*>(src)[from];
    }
  };
  if (header.tiled) {
    for (int t = 0; t < image.num_tiles; ++t) {
      const EXRTile& tile = image.tiles[t];
      if (tile.level_x != 0 || tile.level_y != 0) continue;  // the full-resolution level only
      for (int j = 0; j < tile.height; ++j)
        for (int i = 0; i < tile.width; ++i) {
          const long x = long(tile.offset_x) * header.tile_size_x + i;
          const long y = long(tile.offset_y) * header.tile_size_y + j;
          if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
          for (int c = 0; c < header.num_channels; ++c)
            copy(c, tile.images[c], size_t(j) * header.tile_size_x + i,
                 size_t(y) * image.width + x);
        }
    }
  } else if (image.images) {
    for (int c = 0; c < header.num_channels; ++c)
      for (size_t i = 0; i < n; ++i) copy(c, image.images[c], i, i);
  }
  FreeEXRImage(&image);
  // the image is the display window (the probe checked its size): the data window's pixels in
  // their place, those it does not cover 0, as OpenEXR's readers leave them; the pixels beyond
  // it (overscan) are dropped
  const EXRBox2i dw = header.data_window, sw = header.display_window;
  FreeEXRHeader(&header);
  if (!exr_windows_equal(dw, sw)) {
    const ExrWindowSize shown = exr_window_size(sw);
    const std::int64_t w = shown.width, h = shown.height;
    const std::int64_t dx = std::int64_t(dw.min_x) - sw.min_x,
                       dy = std::int64_t(dw.min_y) - sw.min_y;
    auto place = [&](auto& plane) {
      if (plane.empty()) return;
      std::remove_reference_t<decltype(plane)> shown(static_cast<size_t>(w * h), 0);
      for (std::int64_t y = 0; y < out.height; ++y) {
        if (y + dy < 0 || y + dy >= h) continue;
        for (std::int64_t x = 0; x < out.width; ++x)
          if (x + dx >= 0 && x + dx < w)
            shown[static_cast<size_t>((y + dy) * w + x + dx)] =
                plane[static_cast<size_t>(y * out.width + x)];
      }
      plane = std::move(shown);
    };
    for (auto& plane : out.planes) place(plane);
    for (auto& plane : out.uint_planes) place(plane);
    out.width = static_cast<int>(w);
    out.height = static_cast<int>(h);
  }
  return out;
}

Decoded decode_image(const unsigned char* data, std::size_t size, const std::string& path,
                     int channels, std::uint64_t max_pixels) {
  const Fail fail{path};
  Probe p = probe_image(data, size, path, max_pixels);
  Decoded out;
  out.format = p.format;
  out.channels = channels;
  auto allocate = [&](int w, int h) {
    out.width = w;
    out.height = h;
    out.pixels.assign(static_cast<size_t>(w) * h * channels, 1.0f);
  };
  if (p.format == Format::Pfm) {
    PfmLayout layout;
    probe_pfm(data, size, path, max_pixels, layout);
    const std::uint64_t offset = layout.data_offset;
    const int ch = layout.channels;
    allocate(p.width, p.height);
    const unsigned char* src = data + offset;
    for (int y = 0; y < p.height; ++y)  // PFM rows run bottom to top
      for (int x = 0; x < p.width; ++x)
        for (int c = 0; c < 3; ++c) {
          float v;
          const size_t i = (static_cast<size_t>(y) * p.width + x) * ch + (ch == 3 ? c : 0);
          // a positive scale marks big-endian floats (the scale's magnitude is not applied)
          unsigned char b[4] = {src[4 * i], src[4 * i + 1], src[4 * i + 2], src[4 * i + 3]};
          if (layout.big_endian) std::swap(b[0], b[3]), std::swap(b[1], b[2]);
          std::memcpy(&v, b, 4);
          out.pixels[(static_cast<size_t>(p.height - 1 - y) * p.width + x) * channels + c] = v;
        }
    return out;
  }
  if (p.format == Format::Exr) {
    ExrChannels exr = read_exr_channels(data, size, path, max_pixels);
    int src[3] = {exr.find("R"), exr.find("G"), exr.find("B")};
    // some of R, G and B: the others are 0, as OpenEXR's RGBA reader fills them (a file of R
    // alone was read as grey)
    if (src[0] < 0 && src[1] < 0 && src[2] < 0) {
      // a single channel (Y, or anything else) is grey; luminance with chroma (Y, RY, BY: a
      // colour image) is not, and its colour would be lost
      if (exr.find("RY") >= 0 || exr.find("BY") >= 0)
        fail(
            "OpenEXR file is luminance/chroma (Y, RY, BY channels), which lucent does not read; "
            "save it as RGB");
      int grey = exr.find("Y");
      if (grey < 0 && exr.names.size() == 1) grey = 0;
      if (grey < 0) fail("OpenEXR file has no R, G, B or Y channels");
      src[0] = src[1] = src[2] = grey;
    }
    allocate(exr.width, exr.height);
    const size_t n = static_cast<size_t>(exr.width) * exr.height;
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        out.pixels[i * channels + c] = src[c] >= 0 ? exr.planes[src[c]][i] : 0.0f;
    return out;
  }

  // stb_image's flip setting is the process's (the application's: the library is shared, and
  // lucent set it to 0 before each read, for the application too); rows come top first here
  // whatever it is, read after each decode and undone (a thread's own setting, which overrides
  // the process's, turned textures upside down)
  const int len = static_cast<int>(std::min<std::size_t>(size, 0x7fffffff));
  int w = 0, h = 0, n = 0;
  if (p.format == Format::Hdr) {
    std::unique_ptr<float, StbFree> px(stbi_loadf_from_memory(data, len, &w, &h, &n, channels));
    if (!px) fail("cannot decode Radiance HDR: " + stb_reason());
    allocate(w, h);
    std::copy(px.get(), px.get() + out.pixels.size(), out.pixels.begin());
  } else if (p.sixteen_bit) {
    std::unique_ptr<stbi_us, StbFree> px(stbi_load_16_from_memory(data, len, &w, &h, &n, channels));
    if (!px) fail("cannot decode PNG: " + stb_reason());
    allocate(w, h);
    for (size_t i = 0; i < out.pixels.size(); ++i) {
      double v = px.get()[i] / 65535.0;
      out.pixels[i] = static_cast<float>(i % channels == 3 ? v : srgb_to_linear(v));
    }
  } else {
    std::vector<unsigned char> padded;
    std::array<unsigned char, 3> padding{};
    if (p.short_palette.entries > 0) padded = pad_palette(data, size, p, &padding);
    std::unique_ptr<stbi_uc, StbFree> px(
        padded.empty() ? stbi_load_from_memory(data, len, &w, &h, &n, channels)
                       : stbi_load_from_memory(padded.data(), static_cast<int>(padded.size()), &w,
                                               &h, &n, channels));
    if (!px) fail(std::string("cannot decode ") + format_name(p.format) + ": " + stb_reason());
    if (!padded.empty() && w == p.width && h == p.height)
      for (std::size_t i = 0; i < std::size_t(w) * std::size_t(h); ++i)
        if (std::equal(padding.begin(), padding.end(), px.get() + i * channels))
          fail(std::string(format_name(p.format)) + " pixel (" + std::to_string(i % w) + ", " +
               std::to_string(stb_flips_on_load() ? h - 1 - int(i / w) : int(i / w)) +
               ") names a colour past the " + std::to_string(p.short_palette.entries) +
               " entries of its palette (corrupt)");
    allocate(w, h);
    for (size_t i = 0; i < out.pixels.size(); ++i) {
      stbi_uc v = px.get()[i];
      out.pixels[i] = i % channels == 3 ? v / 255.0f : srgb8_to_linear(v);
    }
  }
  if (w != p.width || h != p.height)
    fail(std::string(format_name(p.format)) + " decoded to " + std::to_string(w) + "x" +
         std::to_string(h) + " pixels, its header claims " + std::to_string(p.width) + "x" +
         std::to_string(p.height));
  if (stb_flips_on_load()) {
    const std::size_t row = std::size_t(w) * std::size_t(channels);
    for (int y = 0; y < h / 2; ++y)
      std::swap_ranges(out.pixels.begin() + std::ptrdiff_t(row * std::size_t(y)),
                       out.pixels.begin() + std::ptrdiff_t(row * std::size_t(y + 1)),
                       out.pixels.begin() + std::ptrdiff_t(row * std::size_t(h - 1 - y)));
  }
  return out;
}

}  // namespace lucent::image_detail
