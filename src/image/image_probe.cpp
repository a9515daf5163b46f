// Image headers checked before any pixel is allocated: the format from the magic bytes, the size
// the header claims against the pixel limit and against what the file can hold (decoding:
// image_decode.cpp).
#include "image/image_probe.hpp"

#include <tinyexr.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

#include "core/file_io.hpp"
#include "core/host_memory.hpp"
#include "lucent/error.hpp"

namespace lucent::image_detail {

namespace {

using u64 = std::uint64_t;

// Reads of fixed-size fields; callers check the length first.
u64 be16(const unsigned char* p) { return (u64(p[0]) << 8) | p[1]; }
u64 be32(const unsigned char* p) { return (be16(p) << 16) | be16(p + 2); }
u64 le16(const unsigned char* p) { return (u64(p[1]) << 8) | p[0]; }
u64 le32(const unsigned char* p) { return (le16(p + 2) << 16) | le16(p); }

bool starts_with(const unsigned char* d, std::size_t n, const char* magic, std::size_t len) {
  return n >= len && std::memcmp(d, magic, len) == 0;
}

class Checker {
 public:
  Checker(const unsigned char* d, std::size_t n, const std::string& path, u64 max_pixels)
      : d_(d), n_(n), path_(path), max_pixels_(max_pixels) {}

  [[noreturn]] void fail(const std::string& what) const { throw Error(path_ + ": " + what); }

  /// Checks the claimed size against the pixel limit (before anything else is computed).
  void size(Probe& p, u64 w, u64 h) const {
    const char* fmt = format_name(p.format);
    if (w == 0 || h == 0)
      fail(std::string(fmt) + " header claims an empty image (" + std::to_string(w) + "x" +
           std::to_string(h) + ")");
    if (w > (1u << 30) || h > (1u << 30) || w * h > max_pixels_)
      fail(std::string(fmt) + " header claims " + std::to_string(w) + "x" + std::to_string(h) +
           " pixels, more than the limit of " + std::to_string(max_pixels_) +
           " pixels (corrupt, or too large)");
    // stb_image's own limit (STBI_MAX_DIMENSIONS): it said only "too large"
    const u64 side = u64(1) << 24;
    if (p.format != Format::Pfm && p.format != Format::Exr && (w > side || h > side))
      fail(std::string(fmt) + " header claims " + std::to_string(w) + "x" + std::to_string(h) +
           " pixels: lucent reads " + fmt + " files of at most " + std::to_string(side) +
           " pixels a side (PFM and OpenEXR files are not limited so)");
    p.width = static_cast<int>(w);
    p.height = static_cast<int>(h);
  }

  /// The file holds `have` bytes where the header needs at least `need`.
  void need(const Probe& p, u64 need, u64 have, const char* what) const {
    if (have < need)
      fail(std::string(format_name(p.format)) + " file is truncated: its " +
           std::to_string(p.width) + "x" + std::to_string(p.height) + " header needs " +
           std::to_string(need) + " bytes of " + what + ", the file has " + std::to_string(have));
  }

  /// A compressed stream of `have` bytes cannot expand to more than `ratio` times its size.
  void ratio(const Probe& p, u64 raw, u64 have, u64 ratio, const char* what) const {
    const u64 slack = 1u << 20;
    if (raw > slack && raw / ratio > have)
      fail(std::string(format_name(p.format)) + " header claims " + std::to_string(p.width) + "x" +
           std::to_string(p.height) + " pixels (" + std::to_string(raw) + " bytes), more than " +
           std::to_string(have) + " bytes of " + what + " can hold (truncated or corrupt)");
  }

  Probe png() const {
    Probe p{Format::Png};
    if (n_ < 33 || be32(d_ + 8) != 13 || std::memcmp(d_ + 12, "IHDR", 4) != 0)
      fail("PNG file has no IHDR header (truncated or corrupt)");
    const unsigned char* h = d_ + 16;
    const u64 depth = h[8], type = h[9];
    int channels = 0;
    switch (type) {
      case 0:
        channels = 1;
        break;
      case 2:
        channels = 3;
        break;
      case 3:
        channels = 1;
        break;
      case 4:
        channels = 2;
        break;
      case 6:
        channels = 4;
        break;
      default:
        fail("PNG header has an invalid colour type " + std::to_string(type));
    }
    if (depth != 1 && depth != 2 && depth != 4 && depth != 8 && depth != 16)
      fail("PNG header has an invalid bit depth " + std::to_string(depth));
    size(p, be32(h), be32(h + 4));
    p.sixteen_bit = depth == 16;
    // walk the chunks: every one must lie inside the file; sum the compressed image data
    u64 idat = 0, pos = 8;
    bool end = false;
    while (pos + 12 <= n_) {
      const u64 len = be32(d_ + pos);
      if (len > n_ - pos - 12)
        fail("PNG file is truncated: the chunk at byte " + std::to_string(pos) + " needs " +
             std::to_string(len) + " bytes, the file has " + std::to_string(n_ - pos - 12));
      // the first PLTE before the image data, as stb_image reads it (of 1 to 256 entries)
      const u64 names = std::min<u64>(256, u64(1) << depth);
      if (type == 3 && idat == 0 && p.short_palette.length_field == 0 &&
          std::memcmp(d_ + pos + 4, "PLTE", 4) == 0 && len % 3 == 0 && len > 0 && len / 3 < names)
        p.short_palette = {len / 3, names, 3, pos + 8, pos};
      if (std::memcmp(d_ + pos + 4, "IDAT", 4) == 0) idat += len;
      if (std::memcmp(d_ + pos + 4, "IEND", 4) == 0) {
        end = true;
        break;
      }
      pos += 12 + len;
    }
    if (!end) fail("PNG file is truncated: no IEND chunk");
    const u64 row = (u64(p.width) * channels * depth + 7) / 8 + 1;
    ratio(p, row * u64(p.height), idat, 1032, "deflate data");  // deflate expands at most 1032x
    return p;
  }

  Probe jpeg() const {
    Probe p{Format::Jpeg};
    u64 pos = 2;
    bool frame = false, scan = false, progressive = false;
    unsigned tables = 0;     // Huffman tables defined so far: bit 4 * class + id
    unsigned quantised = 0;  // quantisation tables defined so far: bit id
    std::vector<std::pair<unsigned, unsigned>> components;  // the frame's: id, quantisation table
    while (true) {
      if (pos >= n_) break;
      if (d_[pos] != 0xFF) {
        if (!scan) fail("JPEG file is corrupt: no marker at byte " + std::to_string(pos));
        ++pos;  // entropy-coded data
        continue;
      }
      while (pos < n_ && d_[pos] == 0xFF) ++pos;  // fill bytes
      if (pos >= n_) break;
      const unsigned m = d_[pos++];
      if (m == 0x00 || (m >= 0xD0 && m <= 0xD7) || m == 0x01) continue;  // stuffing, RSTn, TEM
      if (m == 0xD9) {
        if (!frame || !scan) fail("JPEG file has no image data before its end marker");
        const u64 px = u64(p.width) * u64(p.height);
        // every 8x8 block of the full-resolution component takes a Huffman code of at least one
        // bit for its DC coefficient and, in a baseline scan, one for its AC coefficients (an
        // end-of-block at least): 256 pixels a byte at best, 512 for a progressive file (its AC
        // scans may skip runs of blocks). A 96 KB file claiming 8192x8192 decoded to 1 GiB of
        // stripes.
        const u64 per_byte = progressive ? 512 : 256;
        if (px > (1u << 20) && px / per_byte > n_)
          fail("JPEG header claims " + std::to_string(p.width) + "x" + std::to_string(p.height) +
               " pixels, more than " + std::to_string(n_) + " bytes can hold (corrupt)");
        return p;
      }
      if (pos + 2 > n_) break;
      const u64 len = be16(d_ + pos);
      if (len < 2 || pos + len > n_) break;
      const bool sof = (m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC);
      if (sof) {
        if (len < 8) fail("JPEG frame header is too short");
        if (!frame) {
          size(p, be16(d_ + pos + 5), be16(d_ + pos + 3));
          for (u64 k = 0; k < d_[pos + 7] && 8 + 3 * k + 3 <= len; ++k)
            components.emplace_back(d_[pos + 8 + 3 * k], d_[pos + 10 + 3 * k]);
        }
        frame = true;
        progressive = progressive || m == 0xC2;
      }
      if (m == 0xDA) {
        if (!frame) fail("JPEG file has image data before its frame header");
        scan_tables(pos - 2, pos + 2, len - 2, progressive, tables);
        scan_quantisation(pos - 2, pos + 2, len - 2, components, quantised);
        scan = true;
      }
      if (m == 0xC4) tables |= huffman_tables(pos + 2, len - 2);
      if (m == 0xDB) quantised |= quantisation_tables(pos + 2, len - 2);
      pos += len;
    }
    fail("JPEG file is truncated: no end-of-image marker");
  }

  // A scan header (SOS at byte `at`, its segment from `pos`): every Huffman table its decoding
  // reads must have been defined by a DHT segment before it. stb_image keeps its tables in
  // memory it does not clear, and a table no DHT defined sends its decoder past its arrays
  // (found by fuzzing). A baseline scan reads its components' DC and AC tables; a progressive
  // scan the DC tables for a first DC scan (Ss = 0, Ah = 0), the AC tables for an AC scan.
  void scan_tables(u64 at, u64 pos, u64 left, bool progressive, unsigned tables) const {
    if (left < 1) return;
    const unsigned count = d_[pos];
    if (left < 1 + 2 * u64(count) + 3) return;  // stb_image refuses the header itself
    const unsigned ss = d_[pos + 1 + 2 * count], ah = d_[pos + 3 + 2 * count] >> 4;
    const bool dc = !progressive || (ss == 0 && ah == 0), ac = !progressive || ss > 0;
    for (unsigned k = 0; k < count; ++k) {
      const unsigned sel = d_[pos + 2 + 2 * k], td = sel >> 4, ta = sel & 15;
      if (td > 3 || ta > 3) return;  // stb_image refuses the header itself
      for (unsigned cls = 0; cls < 2; ++cls) {
        const unsigned id = cls == 0 ? td : ta;
        if ((cls == 0 ? dc : ac) && !(tables & (1u << (4 * cls + id))))
          fail("JPEG scan at byte " + std::to_string(at) + " uses Huffman table " +
               (cls == 0 ? "DC" : "AC") + std::to_string(id) +
               ", which no DHT segment before it defines (corrupt)");
      }
    }
  }

  // A scan header (SOS at byte `at`): the quantisation table of each of its components must have
  // been defined by a DQT segment before it. stb_image dequantises with a table no DQT defined
  // from memory it never set (a file that named table 3 decoded to a grey that valgrind traced
  // to uninitialised values).
  void scan_quantisation(u64 at, u64 pos, u64 left,
                         const std::vector<std::pair<unsigned, unsigned>>& components,
                         unsigned quantised) const {
    if (left < 1) return;
    const unsigned count = d_[pos];
    for (unsigned k = 0; k < count && 1 + 2 * u64(k) < left; ++k)
      for (const auto& [id, table] : components)
        if (id == d_[pos + 1 + 2 * k] && table <= 3 && !(quantised & (1u << table)))
          fail("JPEG scan at byte " + std::to_string(at) + " uses quantisation table " +
               std::to_string(table) + ", which no DQT segment before it defines (corrupt)");
  }

  // A DQT segment's tables, read as stb_image reads them: returns the tables it defines (bit id).
  unsigned quantisation_tables(u64 pos, u64 left) const {
    unsigned defined = 0;
    while (left > 0 && pos < n_) {
      const unsigned q = d_[pos], precision = q >> 4, id = q & 15;
      if (precision > 1 || id > 3) return defined;  // stb_image refuses the table itself
      const u64 bytes = precision ? 129 : 65;
      if (bytes > left) return defined;  // stb_image refuses a segment that ends inside a table
      defined |= 1u << id;
      pos += bytes;
      left -= bytes;
    }
    return defined;
  }

  // A DHT segment's tables, read as stb_image reads them (on past the segment if its length
  // lies): more than 256 codes in one table overflow stb_image's arrays (found by fuzzing).
  // Returns the tables it defines (bit 4 * class + id).
  unsigned huffman_tables(u64 pos, u64 left) const {
    unsigned defined = 0;
    auto get8 = [&]() -> unsigned { return pos < n_ ? d_[pos++] : (++pos, 0u); };
    while (left > 0 && left < (1u << 16)) {
      const unsigned q = get8();
      if ((q >> 4) > 1 || (q & 15) > 3) return defined;  // stb_image refuses the table itself
      u64 codes = 0;
      for (int i = 0; i < 16; ++i) codes += get8();
      if (codes > 256)
        fail("JPEG Huffman table at byte " + std::to_string(pos - 17) + " has " +
             std::to_string(codes) + " codes, more than 256 (corrupt)");
      pos += codes;
      defined |= 1u << (4 * (q >> 4) + (q & 15));
      if (17 + codes > left) return defined;
      left -= 17 + codes;
    }
    return defined;
  }

  Probe bmp() const {
    Probe p{Format::Bmp};
    if (n_ < 26) fail("BMP file is truncated: no complete header");
    const u64 offset = le32(d_ + 10), hsz = le32(d_ + 14);
    u64 w, h, bpp, compression = 0;
    if (hsz == 12) {
      w = le16(d_ + 18);
      h = le16(d_ + 20);
      bpp = le16(d_ + 24);
    } else if (hsz == 40 || hsz == 56 || hsz == 108 || hsz == 124) {
      if (n_ < 34) fail("BMP file is truncated: no complete header");
      const std::int32_t sw = static_cast<std::int32_t>(le32(d_ + 18));
      const std::int32_t sh = static_cast<std::int32_t>(le32(d_ + 22));
      if (sw <= 0) fail("BMP header has an invalid width " + std::to_string(sw));
      w = static_cast<u64>(sw);
      h = sh < 0 ? u64(-static_cast<std::int64_t>(sh)) : u64(sh);  // negative: top-down rows
      bpp = le16(d_ + 28);
      compression = le32(d_ + 30);
    } else {
      fail("BMP header has an unsupported size " + std::to_string(hsz));
    }
    if (bpp != 1 && bpp != 4 && bpp != 8 && bpp != 16 && bpp != 24 && bpp != 32)
      fail("BMP header has an unsupported bit count " + std::to_string(bpp));
    if (compression != 0 && compression != 3)
      fail("BMP compression " + std::to_string(compression) +
           " is not supported (uncompressed and bit-field BMPs are)");
    size(p, w, h);
    const u64 stride = (w * bpp + 31) / 32 * 4;
    const u64 start = std::max<u64>(offset, 14 + hsz);
    need(p, start + stride * h, n_, "header and pixel rows");
    if (bpp <= 8) {
      // the palette's entries as stb_image counts them: from the pixels' offset (an OS/2
      // header's from 24 bytes past its end, as stb_image reads it)
      const std::int64_t entries = hsz == 12 ? (std::int64_t(offset) - 38) / 3
                                             : (std::int64_t(offset) - 14 - std::int64_t(hsz)) / 4;
      if (entries > 0 && u64(entries) < (u64(1) << bpp))
        p.short_palette = {u64(entries), u64(1) << bpp, hsz == 12 ? 3u : 4u, 14 + hsz, 10};
    }
    return p;
  }

  // Radiance RGBE, as stb_image reads it: a header ending in an empty line, "-Y h +X w", then
  // scanlines either flat (4 bytes a pixel) or run-length encoded per component. The encoded
  // stream is walked here: stb_image reads zeros past the end of its input, and a zero-length
  // run then never advances (an endless loop on a truncated or corrupt file).
  Probe hdr() const {
    Probe p{Format::Hdr};
    u64 pos = 0;
    auto line = [&]() {
      u64 e = pos;
      while (e < n_ && d_[e] != '\n') ++e;
      if (e >= n_) fail("Radiance HDR header is truncated");
      std::string s(reinterpret_cast<const char*>(d_ + pos), e - pos);
      pos = e + 1;
      return s;
    };
    line();  // "#?RADIANCE"
    bool rgbe = false;
    for (std::string s; !(s = line()).empty();)
      if (s == "FORMAT=32-bit_rle_rgbe") rgbe = true;
    if (!rgbe) fail("Radiance HDR file is not in the 32-bit_rle_rgbe format");
    const std::string res = line();
    long long hv = 0, wv = 0;
    const char* b = res.c_str();
    const char* e = b + res.size();
    auto number = [&](const char*& q, long long& v) {
      while (q < e && (*q == ' ' || *q == '+')) ++q;  // as strtol reads it
      auto r = std::from_chars(q, e, v);
      if (r.ec != std::errc()) fail("Radiance HDR resolution line '" + res + "' is not -Y h +X w");
      q = r.ptr;
    };
    if (res.compare(0, 3, "-Y ") != 0)
      fail("Radiance HDR resolution line '" + res + "' is not -Y h +X w");
    const char* q = b + 3;
    number(q, hv);
    while (q < e && *q == ' ') ++q;
    if (e - q < 3 || std::strncmp(q, "+X ", 3) != 0)
      fail("Radiance HDR resolution line '" + res + "' is not -Y h +X w");
    q += 3;
    number(q, wv);
    if (hv <= 0 || wv <= 0)
      fail("Radiance HDR header claims an empty image (" + std::to_string(wv) + "x" +
           std::to_string(hv) + ")");
    size(p, u64(wv), u64(hv));
    const u64 w = u64(wv), h = u64(hv);
    if (w < 8 || w >= 32768) {
      need(p, pos + 4 * w * h, n_, "header and pixels");
      return p;
    }
    for (u64 y = 0; y < h; ++y) {
      if (pos + 4 > n_) need(p, pos + 4, n_, "header and scanlines");
      if (d_[pos] != 2 || d_[pos + 1] != 2 || (d_[pos + 2] & 0x80)) {
        // not run-length encoded: stb_image reads the whole image flat from here on (its first
        // pixel included), whatever scanline this is
        need(p, pos + 4 * w * h, n_, "header and pixels");
        return p;
      }
      const u64 len = (u64(d_[pos + 2]) << 8) | d_[pos + 3];
      if (len != w)
        fail("Radiance HDR scanline " + std::to_string(y) + " has length " + std::to_string(len) +
             ", the header says " + std::to_string(w));
      pos += 4;
      for (int k = 0; k < 4; ++k) {
        for (u64 i = 0; i < w;) {
          if (pos >= n_) need(p, pos + 1, n_, "run-length data");
          u64 count = d_[pos++];
          u64 bytes = 1;
          if (count > 128) {
            count -= 128;
          } else {
            bytes = count;
          }
          if (count == 0 || count > w - i)
            fail("Radiance HDR scanline " + std::to_string(y) + " has a bad run length at byte " +
                 std::to_string(pos - 1) + " (corrupt)");
          if (pos + bytes > n_) need(p, pos + bytes, n_, "run-length data");
          pos += bytes;
          i += count;
        }
      }
    }
    return p;
  }

  Probe pfm(u64* data_offset = nullptr, int* channels = nullptr, bool* big_endian = nullptr) const {
    Probe p{Format::Pfm};
    u64 pos = 2;
    auto space = [&](u64 at) { return at < n_ && std::strchr(" \t\r\n", d_[at]) && d_[at]; };
    auto field = [&](const char* what) {
      if (!space(pos)) fail(std::string("PFM header: no ") + what);
      while (space(pos)) ++pos;
      u64 s = pos;
      while (pos < n_ && !space(pos)) ++pos;
      if (s == pos) fail(std::string("PFM header: no ") + what);
      return std::string(reinterpret_cast<const char*>(d_ + s), pos - s);
    };
    auto integer = [&](const char* what) {
      std::string s = field(what);
      long long v = 0;
      auto r = std::from_chars(s.data(), s.data() + s.size(), v);
      if (r.ec != std::errc() || r.ptr != s.data() + s.size() || v <= 0)
        fail(std::string("PFM header: ") + what + " '" + s + "' is not a positive integer");
      return u64(v);
    };
    const u64 w = integer("width"), h = integer("height");
    std::string sc = field("scale");
    double scale = 0;
    auto r = std::from_chars(sc.data(), sc.data() + sc.size(), scale);
    if (r.ec != std::errc() || r.ptr != sc.data() + sc.size() || !std::isfinite(scale) ||
        scale == 0)
      fail("PFM header: scale '" + sc + "' is not a finite non-zero number");
    if (!space(pos)) fail("PFM header: no pixel data");
    // The scale's line ends the header: spaces, tabs or a CR may precede its newline ("\r\n" from
    // Windows). Without a newline, one whitespace byte. The pixels must then fill the rest of
    // the file exactly: a header end misread by a byte would shift every float.
    u64 end = pos;
    while (end < n_ && (d_[end] == ' ' || d_[end] == '\t' || d_[end] == '\r')) ++end;
    pos = end < n_ && d_[end] == '\n' ? end + 1 : pos + 1;
    size(p, w, h);
    const int ch = d_[1] == 'F' ? 3 : 1;
    need(p, pos + w * h * ch * 4, n_, "header and pixels");
    if (n_ > pos + w * h * ch * 4)
      fail("PFM file has " + std::to_string(n_ - pos - w * h * ch * 4) + " bytes after its " +
           std::to_string(w) + "x" + std::to_string(h) +
           " pixels (a header it misreads, or a corrupt file)");
    if (data_offset) *data_offset = pos;
    if (channels) *channels = ch;
    if (big_endian) *big_endian = scale > 0;
    return p;
  }

  Probe tga() const {
    Probe p{Format::Tga};
    const char* unknown =
        "unknown image format (lucent reads PNG, JPEG, BMP, TGA, Radiance HDR, PFM and OpenEXR)";
    if (n_ < 18) fail(unknown);
    const unsigned idlen = d_[0], cmap = d_[1], type = d_[2];
    const u64 cmap_len = le16(d_ + 5), cmap_bits = d_[7], bpp = d_[16];
    const u64 w = le16(d_ + 12), h = le16(d_ + 14);
    auto bits_ok = [](u64 b) { return b == 8 || b == 15 || b == 16 || b == 24 || b == 32; };
    bool ok = cmap <= 1 && w > 0 && h > 0 && bits_ok(bpp);
    if (cmap == 1)
      ok = ok && (type == 1 || type == 9) && bits_ok(cmap_bits) && (bpp == 8 || bpp == 16);
    else
      ok = ok && (type == 2 || type == 3 || type == 10 || type == 11);
    if (!ok) fail(unknown);
    size(p, w, h);
    const u64 px_bytes = (bpp + 7) / 8;
    u64 pos = 18 + idlen + (cmap == 1 ? cmap_len * ((cmap_bits + 7) / 8) : 0);
    const u64 total = w * h;
    if (type < 8) {
      need(p, pos + total * px_bytes, n_, "header and pixels");
      return p;
    }
    for (u64 px = 0; px < total;) {
      if (pos >= n_) need(p, pos + 1, n_, "run-length data");
      const unsigned hdr = d_[pos++];
      const u64 count = (hdr & 0x7F) + 1;
      pos += (hdr & 0x80) ? px_bytes : count * px_bytes;
      if (pos > n_) need(p, pos, n_, "run-length data");
      px += count;
    }
    return p;
  }

  Probe probe() const {
    static const char kPng[] = "\x89PNG\r\n\x1a\n";
    if (starts_with(d_, n_, kPng, 8)) return png();
    if (starts_with(d_, n_, "\xFF\xD8\xFF", 3)) return jpeg();
    if (starts_with(d_, n_, "BM", 2)) return bmp();
    if (starts_with(d_, n_, "#?RADIANCE\n", 11) || starts_with(d_, n_, "#?RGBE\n", 7)) return hdr();
    if (n_ >= 3 && d_[0] == 'P' && (d_[1] == 'F' || d_[1] == 'f') &&
        std::strchr(" \t\r\n", d_[2]) && d_[2])
      return pfm();
    if (starts_with(d_, n_, "\x76\x2f\x31\x01", 4)) return exr(nullptr);
    if (n_ == 0) fail("empty image file");
    const char* other = starts_with(d_, n_, "GIF8", 4)               ? "GIF"
                        : starts_with(d_, n_, "8BPS", 4)             ? "PSD"
                        : starts_with(d_, n_, "\x53\x80\xF6\x34", 4) ? "Softimage PIC"
                        : (n_ >= 2 && d_[0] == 'P' && d_[1] >= '1' && d_[1] <= '7') ? "PNM"
                                                                                    : nullptr;
    if (other)
      fail(std::string(other) +
           " images are not supported (lucent reads PNG, JPEG, BMP, TGA, Radiance HDR, PFM and "
           "OpenEXR)");
    return tga();
  }

  // The header through tinyexr (`header` filled when given; the caller frees it).
  Probe exr(EXRHeader* out) const {
    Probe p{Format::Exr};
    EXRVersion version;
    if (ParseEXRVersionFromMemory(&version, d_, n_) != TINYEXR_SUCCESS)
      fail("OpenEXR file has an invalid version field");
    if (version.multipart || version.non_image)
      fail("multi-part and deep OpenEXR files are not supported");
    exr_attribute_sizes();
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    if (ParseEXRHeaderFromMemory(&header, &version, d_, n_, &err) != TINYEXR_SUCCESS) {
      FreeEXRHeader(&header);
      fail("cannot read OpenEXR header: " + exr_message(err));
    }
    struct Free {
      EXRHeader* h;
      bool keep;
      ~Free() {
        if (!keep) FreeEXRHeader(h);
      }
    } guard{&header, false};
    // a window's size, refused when empty; the size the probe checks (its width and height)
    auto window = [&](const EXRBox2i& b, const char* which) {
      const ExrWindowSize s = exr_window_size(b);
      if (s.width <= 0 || s.height <= 0)
        fail(std::string("OpenEXR header claims an empty ") + which + " window (" +
             std::to_string(s.width) + "x" + std::to_string(s.height) + ")");
      size(p, u64(s.width), u64(s.height));
      return s;
    };
    const EXRBox2i& dw = header.data_window;
    const ExrWindowSize data = window(dw, "data");
    const std::int64_t w = data.width, h = data.height;
    if (header.num_channels <= 0) fail("OpenEXR header has no channels");
    p.channels = header.num_channels;
    p.compression = header.compression_type;
    for (int a = 0; a < header.num_custom_attributes; ++a)
      if (std::strcmp(header.custom_attributes[a].name, "lucent.checksum") == 0)
        p.lucent_part = true;
    u64 bytes_per_pixel = 0;
    for (int c = 0; c < header.num_channels; ++c)
      bytes_per_pixel += header.pixel_types[c] == TINYEXR_PIXELTYPE_HALF ? 2 : 4;
    u64 chunks;
    if (header.tiled) {
      if (header.tile_size_x <= 0 || header.tile_size_y <= 0)
        fail("OpenEXR header has an invalid tile size");
      chunks = tile_chunks(p, header, u64(w), u64(h));  // checks the offset table's extent too
    } else {
      int lines = 1;
      switch (header.compression_type) {
        case TINYEXR_COMPRESSIONTYPE_ZIP:
        case TINYEXR_COMPRESSIONTYPE_ZFP:  // tinyexr's own, 16 lines as tinyexr counts them
                                           // (its header parser refuses it unless built with ZFP)
          lines = 16;
          break;
        case TINYEXR_COMPRESSIONTYPE_PIZ:
          lines = 32;
          break;
        default:
          lines = 1;
      }
      chunks = (u64(h) + lines - 1) / lines;
      // tinyexr 1.0.1 sizes a scanline image's offset table by its chunkCount attribute when
      // the header has one, and allocates it (8 bytes an entry) before reading any entry: a
      // 735-byte file asked for 3.6 GB (found by fuzz_render_image). A single-part scanline
      // image has exactly one chunk per block of lines, so another count is a damaged header.
      if (header.chunk_count > 0 && u64(header.chunk_count) != chunks)
        fail("OpenEXR header's chunkCount is " + std::to_string(header.chunk_count) + ", but its " +
             std::to_string(h) + " scanlines make " + std::to_string(chunks) + " chunks");
      // the offset table follows the magic number, the version and the header
      need(p, 8 + u64(header.header_len) + 8 * chunks, n_, "header and offset table");
    }
    if (header.compression_type == TINYEXR_COMPRESSIONTYPE_PIZ) {
      if (header.tiled) fail("tiled PIZ-compressed OpenEXR files are not supported");
      piz_chunks(header, u64(w), chunks, bytes_per_pixel);
    }
    // zlib expands at most 1032x; PIZ's Huffman runs a few hundred times
    ratio(p, u64(w) * u64(h) * bytes_per_pixel, n_, 2048, "file");
    // the image is the display window: a data window of a part of it (a crop), or beyond it
    // (overscan), was read as the image, stretched or shifted (read_exr_channels places it)
    if (!exr_windows_equal(dw, header.display_window)) {
      const ExrWindowSize shown = window(header.display_window, "display");
      p.decode_pixels = u64(w) * u64(h) + u64(shown.width) * u64(shown.height);
    }
    if (out) {
      *out = header;
      guard.keep = true;
    }
    return p;
  }

  // tinyexr 1.0.1 takes a tile's coordinates from its chunk unchecked and multiplies them by the
  // tile size in int (signed overflow: found by fuzz_texture and fuzz_render_image from a tiled
  // seed), and rebuilds an offset table with an entry <= 0 by walking the chunks unchecked. So
  // the levels and tile grids of a tiled file are computed as tinyexr computes them, every entry
  // of the offset table must point at a chunk inside the file, and every chunk must name a tile
  // of the grid of the level its entry belongs to. The tile buffers tinyexr allocates (every tile
  // of every level, each at the full tile size) count against the pixel limit. Returns the
  // number of entries of the offset table.
  u64 tile_chunks(const Probe& p, const EXRHeader& header, u64 w, u64 h) const {
    const int mode = header.tile_level_mode, rounding = header.tile_rounding_mode;
    if (mode != TINYEXR_TILE_ONE_LEVEL && mode != TINYEXR_TILE_MIPMAP_LEVELS &&
        mode != TINYEXR_TILE_RIPMAP_LEVELS)
      fail("OpenEXR header has an unknown tile level mode " + std::to_string(mode));
    if (rounding != TINYEXR_TILE_ROUND_DOWN && rounding != TINYEXR_TILE_ROUND_UP)
      fail("OpenEXR header has an unknown tile rounding mode " + std::to_string(rounding));
    const bool up = rounding == TINYEXR_TILE_ROUND_UP;
    auto log2 = [&](u64 x) {  // floor, or ceil when rounding up
      int y = 0;
      bool rest = false;
      for (; x > 1; x >>= 1, ++y) rest = rest || (x & 1);
      return y + (up && rest ? 1 : 0);
    };
    auto level_size = [&](u64 top, int l) {
      const u64 b = u64(1) << l;
      const u64 s = top / b + (up && top % b ? 1 : 0);
      return std::max<u64>(s, 1);
    };
    const int x_levels = mode == TINYEXR_TILE_ONE_LEVEL       ? 1
                         : mode == TINYEXR_TILE_MIPMAP_LEVELS ? log2(std::max(w, h)) + 1
                                                              : log2(w) + 1;
    const int y_levels = mode == TINYEXR_TILE_RIPMAP_LEVELS ? log2(h) + 1 : x_levels;
    const u64 tx = u64(header.tile_size_x), ty = u64(header.tile_size_y);
    std::vector<u64> nx(x_levels), ny(y_levels);
    for (int l = 0; l < x_levels; ++l) nx[l] = (level_size(w, l) + tx - 1) / tx;
    for (int l = 0; l < y_levels; ++l) ny[l] = (level_size(h, l) + ty - 1) / ty;
    std::vector<std::pair<int, int>> levels;  // (x level, y level) in the offset table's order
    if (mode == TINYEXR_TILE_RIPMAP_LEVELS) {
      for (int ly = 0; ly < y_levels; ++ly)
        for (int lx = 0; lx < x_levels; ++lx) levels.emplace_back(lx, ly);
    } else {
      for (int l = 0; l < x_levels; ++l) levels.emplace_back(l, l);
    }
    u64 entries = 0, pixels = 0;
    for (const auto& [lx, ly] : levels) {
      entries += nx[lx] * ny[ly];
      if (tx > (1u << 30) || ty > (1u << 30) || nx[lx] * tx > (u64(1) << 31) ||
          ny[ly] * ty > (u64(1) << 31))
        pixels = max_pixels_ + 1;
      else
        pixels += nx[lx] * tx * ny[ly] * ty;
      if (pixels > max_pixels_)
        fail("OpenEXR tiles of " + std::to_string(tx) + "x" + std::to_string(ty) + " for a " +
             std::to_string(w) + "x" + std::to_string(h) + " image take more than the limit of " +
             std::to_string(max_pixels_) + " pixels (corrupt, or too large)");
    }
    const u64 table = 8 + u64(header.header_len), data = table + 8 * entries;
    need(p, data, n_, "header and offset table");
    auto i32 = [&](u64 at) { return static_cast<std::int32_t>(le32(d_ + at)); };
    u64 i = 0;
    for (const auto& [lx, ly] : levels)
      for (u64 k = 0; k < nx[lx] * ny[ly]; ++k, ++i) {
        const u64 offset = le32(d_ + table + 8 * i) | (u64(le32(d_ + table + 8 * i + 4)) << 32);
        if (offset < data || offset > n_ || n_ - offset < 20)
          fail("OpenEXR offset table entry " + std::to_string(i) + " of " +
               std::to_string(entries) + " (" + std::to_string(offset) +
               ") points outside the file's tiles (damaged offset table)");
        const std::int32_t x = i32(offset), y = i32(offset + 4);
        const std::int32_t cx = i32(offset + 8), cy = i32(offset + 12);
        if (cx != lx || cy != ly || x < 0 || y < 0 || u64(x) >= nx[lx] || u64(y) >= ny[ly])
          fail("OpenEXR tile chunk at byte " + std::to_string(offset) + " names tile (" +
               std::to_string(x) + ", " + std::to_string(y) + ") of level (" + std::to_string(cx) +
               ", " + std::to_string(cy) + "), not one of the " + std::to_string(nx[lx]) + "x" +
               std::to_string(ny[ly]) + " tiles of level (" + std::to_string(lx) + ", " +
               std::to_string(ly) + ")");
      }
    return entries;
  }

  // tinyexr 1.0.1 reads the value of two header attributes without checking its size: "tiles"
  // as 9 bytes (a 1-byte one is a heap over-read, found by fuzz_texture) and "compression" as 1.
  // The header's attributes (name, type, int32 size, value; a null byte ends the list) are
  // walked first and those two must have their sizes; a header that ends early is left to
  // tinyexr's own error.
  void exr_attribute_sizes() const {
    std::size_t pos = 8;  // magic number and version
    auto cstring = [&](std::string* out) {
      const void* end = pos < n_ ? std::memchr(d_ + pos, 0, n_ - pos) : nullptr;
      if (!end) return false;
      const std::size_t len = static_cast<const unsigned char*>(end) - (d_ + pos);
      out->assign(reinterpret_cast<const char*>(d_ + pos), len);
      pos += len + 1;
      return true;
    };
    while (pos < n_ && d_[pos] != 0) {
      std::string name, type;
      if (!cstring(&name) || !cstring(&type) || pos + 4 > n_) return;
      const std::uint32_t size = std::uint32_t(d_[pos]) | std::uint32_t(d_[pos + 1]) << 8 |
                                 std::uint32_t(d_[pos + 2]) << 16 |
                                 std::uint32_t(d_[pos + 3]) << 24;
      pos += 4;
      const std::size_t want = name == "tiles" ? 9 : (name == "compression" ? 1 : 0);
      if (want && size != want)
        fail("OpenEXR header attribute '" + name + "' has " + std::to_string(size) +
             " bytes, not " + std::to_string(want));
      if (size > n_ - pos) return;
      pos += size;
    }
  }

  // tinyexr 1.0.1 reads a PIZ chunk's bitmap, its Huffman length and the Huffman header
  // without checking them against the chunk's size (a heap over-read found by fuzzing): each
  // scanline chunk is checked here as tinyexr will read it.
  void piz_chunks(const EXRHeader& header, u64 width, u64 chunks, u64 bytes_per_pixel) const {
    const u64 table = u64(header.header_len) + 8;
    auto i32 = [&](u64 at) { return static_cast<std::int32_t>(le32(d_ + at)); };
    for (u64 c = 0; c < chunks; ++c) {
      u64 offset = le32(d_ + table + 8 * c) | (u64(le32(d_ + table + 8 * c + 4)) << 32);
      if (offset > n_ || n_ - offset < 8) continue;  // tinyexr refuses these itself
      const std::int64_t line = i32(offset), len = i32(offset + 4);
      if (len <= 0 || u64(len) > n_ - offset - 8) continue;
      const std::int64_t end =
          std::min<std::int64_t>(line + 32, std::int64_t(header.data_window.max_y) + 1);
      if (end <= line) continue;
      if (u64(len) == width * u64(end - line) * bytes_per_pixel) continue;  // stored raw
      const u64 at = offset + 8;
      auto bad = [&](const std::string& why) {
        fail("OpenEXR PIZ chunk at byte " + std::to_string(offset) + " is corrupt: " + why);
      };
      if (len < 4) bad("shorter than its bitmap bounds");
      const u64 lo = le16(d_ + at), hi = le16(d_ + at + 2);
      const u64 bitmap = lo <= hi ? hi - lo + 1 : 0;
      if (4 + bitmap + 4 > u64(len)) bad("its bitmap runs past its end");
      const std::int64_t huffman = i32(at + 4 + bitmap);
      if (huffman < 20 || 4 + bitmap + 4 + u64(huffman) > u64(len))
        bad("its Huffman data size " + std::to_string(huffman) + " does not fit");
      // the Huffman header: im, iM, table length, bit count (int32), reserved; tinyexr computes
      // (8 - bits) & 7 on a negative count (signed overflow at INT_MIN, found by fuzzing)
      const std::int64_t bits = i32(at + 4 + bitmap + 4 + 12);
      if (bits < 0) bad("its Huffman bit count " + std::to_string(bits) + " is negative");
      huffman_code_lengths(at + 4 + bitmap + 4, huffman, bad);
    }
  }

  // The Huffman data starts with im, iM (the first and last symbol of the code table) and the
  // table of code lengths: 6 bits each, MSB first, where 59-62 stand for runs of 2-5 zeros and
  // 63 for a run of 6-261 given by the next 8 bits. tinyexr 1.0.1 ignores the result of its
  // unpacking: a table whose lengths run past the Huffman data, or whose zero run passes iM,
  // leaves a run code (59-63) as a code length, and its decoder then computes (1 << 63) - 1
  // (signed overflow, found by fuzzing). The lengths are read here as tinyexr reads them
  // (bytes past the file as the zeros of its padded copy), and a table it could not unpack is
  // refused. A table with im or iM outside 0..65536 tinyexr refuses itself.
  template <class Bad>
  void huffman_code_lengths(u64 at, std::int64_t size, const Bad& bad) const {
    const std::int64_t im = static_cast<std::int32_t>(le32(d_ + at));
    const std::int64_t iM = static_cast<std::int32_t>(le32(d_ + at + 4));
    const std::int64_t symbols = 65537;
    if (im < 0 || im >= symbols || iM < 0 || iM >= symbols) return;
    const u64 start = at + 20;
    const std::int64_t table_bytes = size - 20;
    u64 p = start, c = 0;
    int lc = 0;
    auto take = [&](int n) {  // the next n bits
      while (lc < n) {
        c = (c << 8) | (p < n_ ? d_[p] : 0);
        ++p;
        lc += 8;
      }
      lc -= n;
      return static_cast<std::int64_t>((c >> lc) & ((u64(1) << n) - 1));
    };
    auto used = [&] { return static_cast<std::int64_t>(p - start); };
    for (std::int64_t k = im; k <= iM; ++k) {
      if (used() >= table_bytes) bad("its Huffman code lengths run past its Huffman data");
      const std::int64_t l = take(6);
      std::int64_t run = 0;
      if (l == 63) {
        if (used() > table_bytes) bad("its Huffman code lengths run past its Huffman data");
        run = take(8) + 6;
      } else if (l >= 59) {
        run = l - 57;
      }
      if (run == 0) continue;
      if (k + run > iM + 1)
        bad("a run of zero code lengths passes the last symbol of its Huffman table");
      k += run - 1;
    }
  }

  const unsigned char* d_;
  std::size_t n_;
  const std::string& path_;
  u64 max_pixels_;
};

}  // namespace

std::string exr_message(const char* err) {
  std::string msg = err ? err : "unknown error";
  if (err) FreeEXRErrorMessage(err);
  for (char& c : msg)
    if (c == '\n') c = ' ';
  while (!msg.empty() && msg.back() == ' ') msg.pop_back();
  return msg;
}

const char* format_name(Format f) {
  switch (f) {
    case Format::Png:
      return "PNG";
    case Format::Jpeg:
      return "JPEG";
    case Format::Bmp:
      return "BMP";
    case Format::Tga:
      return "TGA";
    case Format::Hdr:
      return "Radiance HDR";
    case Format::Pfm:
      return "PFM";
    case Format::Exr:
      return "OpenEXR";
  }
  return "image";
}

Probe probe_image(const unsigned char* data, std::size_t size, const std::string& path,
                  std::uint64_t max_pixels) {
  return Checker(data, size, path, max_pixels).probe();
}

Probe probe_pfm(const unsigned char* data, std::size_t size, const std::string& path,
                std::uint64_t max_pixels, PfmLayout& layout) {
  return Checker(data, size, path, max_pixels)
      .pfm(&layout.data_offset, &layout.channels, &layout.big_endian);
}

Probe probe_exr(const unsigned char* data, std::size_t size, const std::string& path,
                std::uint64_t max_pixels, EXRHeader& header) {
  Checker check(data, size, path, max_pixels);
  if (!starts_with(data, size, "\x76\x2f\x31\x01", 4)) check.fail("not an OpenEXR file");
  return check.exr(&header);
}

void check_decode_memory(const std::string& path, const char* thing, const Probe& p,
                         std::uint64_t bytes_per_pixel, std::uint64_t file_bytes) {
  const std::uint64_t pixels =
      p.decode_pixels > 0 ? p.decode_pixels : std::uint64_t(p.width) * std::uint64_t(p.height);
  const std::uint64_t need = pixels * bytes_per_pixel + file_bytes;
  std::string what;
  const std::uint64_t limit = sys::host_memory_allowed(&what);
  if (limit > 0 && need > limit)
    throw Error(path + ": reading this " + std::to_string(p.width) + "x" +
                std::to_string(p.height) + " " + thing + " needs about " + sys::format_bytes(need) +
                " of memory, more than the limit of " + sys::format_bytes(limit) + " (80% of " +
                what + ")");
}

}  // namespace lucent::image_detail
