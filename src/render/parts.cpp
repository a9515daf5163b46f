// Sample-range renders ("parts") and their exact merge (lucent/parts.hpp). A part file is a render
// EXR (R, G, B, var.*, n: `lucent compare` reads it) with the raw double sums stored bit for bit
// as pairs of UINT channels and the header as string attributes. Format: docs/parts.md.
#include "lucent/parts.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <utility>

#include "core/file_io.hpp"
#include "core/host_memory.hpp"
#include "core/text.hpp"
#include "image/image_probe.hpp"
#include "image/part_sums.hpp"
#include "lucent/error.hpp"
#include "lucent/limits.hpp"
#include "lucent/types.hpp"
#include "render/part_write.hpp"
#include "render/sample_stats.hpp"

namespace lucent {

namespace {

using image_detail::hex64;

constexpr const char* kFormat = "lucent-part 1";

double parse_double(const std::string& path, const std::string& what, const std::string& s) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v))
    throw Error(path + ": attribute " + what + ": invalid number '" + s + "'");
  return v;
}

std::string ranges_attribute(const std::vector<SampleRange>& rs) {
  std::string out;
  for (const SampleRange& r : rs)
    out += (out.empty() ? "" : ",") + std::to_string(r.begin) + ":" + std::to_string(r.end);
  return out;
}

/// "A:B,C:D": sorted, disjoint, non-empty ranges below 2^32.
std::vector<SampleRange> parse_ranges(const std::string& path, const std::string& what,
                                      const std::string& s) {
  std::vector<SampleRange> out;
  size_t at = 0;
  while (at < s.size()) {
    size_t comma = s.find(',', at);
    if (comma == std::string::npos) comma = s.size();
    const std::string item = s.substr(at, comma - at);
    const size_t colon = item.find(':');
    if (colon == std::string::npos)
      throw Error(path + ": attribute " + what + ": '" + item + "' is not a range A:B");
    SampleRange r{
        image_detail::parse_attribute_u64(path, what, item.substr(0, colon), 1ull << 32),
        image_detail::parse_attribute_u64(path, what, item.substr(colon + 1), 1ull << 32)};
    if (r.end <= r.begin || (!out.empty() && r.begin < out.back().end))
      throw Error(path + ": attribute " + what + ": ranges must be non-empty, sorted and disjoint");
    out.push_back(r);
    at = comma + 1;
    // (a trailing comma, "0:4,", was taken for the end of the list)
    if (comma + 1 == s.size())
      throw Error(path + ": attribute " + what + ": '" + s + "' ends in a comma");
  }
  return out;
}

std::uint64_t total(const std::vector<SampleRange>& rs) {
  std::uint64_t n = 0;
  for (const SampleRange& r : rs) n += r.end - r.begin;
  return n;
}

/// Sorted union of two sorted disjoint lists (adjacent ranges joined).
std::vector<SampleRange> unite(std::vector<SampleRange> a, const std::vector<SampleRange>& b) {
  a.insert(a.end(), b.begin(), b.end());
  std::sort(a.begin(), a.end(),
            [](const SampleRange& x, const SampleRange& y) { return x.begin < y.begin; });
  std::vector<SampleRange> out;
  for (const SampleRange& r : a) {
    if (!out.empty() && r.begin <= out.back().end)
      out.back().end = std::max(out.back().end, r.end);
    else
      out.push_back(r);
  }
  return out;
}

/// The first overlap between two sorted disjoint lists, if any: the first range of `a` that
/// overlaps one of `b`, and the first of `b` it overlaps. One pass over both lists: the range
/// that ends first cannot overlap anything after the other's current range. (A pair loop took
/// minutes on two part files of a few MB, whose headers listed 10^5 ranges each.)
bool overlap(const std::vector<SampleRange>& a, const std::vector<SampleRange>& b,
             SampleRange* first_a, SampleRange* first_b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (a[i].begin < b[j].end && b[j].begin < a[i].end) {
      *first_a = a[i];
      *first_b = b[j];
      return true;
    }
    if (a[i].end <= b[j].end)
      ++i;
    else
      ++j;
  }
  return false;
}

/// The checksum of an accumulation's sums (image_detail::part_sums_checksum).
std::uint64_t sums_checksum(const Accumulation& a) {
  return image_detail::part_sums_checksum(a.sum, a.sumsq, a.count);
}

PartInfo info_from_attributes(const std::string& path,
                              const std::map<std::string, std::string>& attrs, int width,
                              int height) {
  auto get = [&](const std::string& key) -> const std::string& {
    auto it = attrs.find("lucent." + key);
    if (it == attrs.end())
      throw Error(path + ": not a lucent part file (no lucent." + key +
                  " attribute; render parts with `lucent render --samples A:B`)");
    return it->second;
  };
  if (get("format") != kFormat)
    throw Error(path + ": unsupported part format '" + get("format") + "' (expected '" + kFormat +
                "')");
  PartInfo info;
  info.width = width;
  info.height = height;
  const std::string film = std::to_string(width) + "x" + std::to_string(height);
  if (get("film") != film)
    throw Error(path + ": attribute lucent.film '" + get("film") + "' differs from the image's " +
                film);
  const std::string& h = get("hash");
  if (h.size() != 16 || h.find_first_not_of("0123456789abcdef") != std::string::npos)
    throw Error(path + ": attribute lucent.hash: invalid hash '" + h + "'");
  info.scene_hash = std::strtoull(h.c_str(), nullptr, 16);
  info.seed = static_cast<std::uint32_t>(
      image_detail::parse_attribute_u64(path, "lucent.seed", get("seed"), 0xffffffffu));
  const auto sampler = attrs.find("lucent.sampler");  // absent from older part files
  if (sampler != attrs.end()) {
    info.sampler = sampler->second;
    if (!find_type<SamplerType>(info.sampler))
      throw Error(path + ": attribute lucent.sampler: unknown sampler '" + info.sampler + "'");
  }
  info.integrator = get("integrator");
  if (!find_type<IntegratorType>(info.integrator))
    throw Error(path + ": attribute lucent.integrator: unknown integrator '" + info.integrator +
                "'");
  info.version = get("version");
  info.scene = get("scene");
  info.samples = parse_ranges(path, "lucent.samples", get("samples"));
  info.requested = parse_ranges(path, "lucent.requested", get("requested"));
  if (info.requested.empty()) throw Error(path + ": attribute lucent.requested: no sample range");
  if (unite(info.requested, info.samples) != info.requested)
    throw Error(path + ": attribute lucent.samples: " + ranges_text(info.samples) +
                " lies outside the requested " + ranges_text(info.requested));
  info.nonfinite = image_detail::parse_attribute_u64(path, "lucent.nonfinite", get("nonfinite"));
  info.rays = image_detail::parse_attribute_u64(path, "lucent.rays", get("rays"));
  info.seconds = parse_double(path, "lucent.seconds", get("seconds"));
  if (info.seconds < 0)  // a merge adds them: a negative time would hide another part's
    throw Error(path + ": attribute lucent.seconds: negative time '" + get("seconds") + "'");
  // display: transfer,gamma,exposure,tonemap
  const std::string& d = get("display");
  io::CNumbers c_numbers;  // "2.2", whatever the process locale (the writer's, part_write)
  char transfer[16] = {0}, tonemap[16] = {0};
  double gamma = 0, exposure = 0;
  int end = 0;  // the whole value (trailing characters, 'clampX', were ignored)
  if (std::sscanf(d.c_str(), "%15[a-z],%lf,%lf,%15[a-z]%n", transfer, &gamma, &exposure, tonemap,
                  &end) != 4 ||
      static_cast<std::size_t>(end) != d.size() || !std::isfinite(gamma) || !(gamma > 0) ||
      !std::isfinite(exposure))
    throw Error(path + ": attribute lucent.display: invalid '" + d + "'");
  const std::string t = transfer, m = tonemap;
  if (t != "srgb" && t != "gamma" && t != "linear")
    throw Error(path + ": attribute lucent.display: unknown transfer '" + t + "'");
  if (m != "clamp" && m != "reinhard" && m != "aces")
    throw Error(path + ": attribute lucent.display: unknown tone map '" + m + "'");
  info.display.transfer =
      t == "srgb" ? Transfer::Srgb : (t == "gamma" ? Transfer::Gamma : Transfer::Linear);
  info.display.gamma = gamma;
  info.display.exposure = exposure;
  info.display.tonemap =
      m == "clamp" ? ToneMap::Clamp : (m == "reinhard" ? ToneMap::Reinhard : ToneMap::Aces);
  return info;
}

std::string channel_name(int plane, int c, bool high) {
  return image_detail::part_channel_name(plane, c, high);
}

/// Whether an accumulation's sums and counts have its film's size (a part made by hand may not:
/// read as they were, they were read past their ends).
bool sums_fit_film(const Accumulation& a) {
  if (a.width < 0 || a.height < 0) return false;
  const size_t npix = static_cast<size_t>(a.width) * a.height;
  return a.sum.size() == npix * 3 && a.sumsq.size() == npix * 3 && a.count.size() == npix;
}

std::string pixel_text(size_t i, int width) {
  return "pixel " + std::to_string(i % width) + ", " + std::to_string(i / width);
}

/// Checks a part's counts against its header. The kernel counts every sample of a pixel either in
/// the pixel's n or as non-finite (a part holds no light-traced caustics, whose paths are counted
/// too), so each pixel holds the part's number of samples (the total of its ranges) less its
/// non-finite ones, and the samples the pixels miss add up to info.nonfinite: true of a rendered
/// part and, the counts, ranges and non-finite counts adding up, of a merge of parts. A part
/// whose counts were altered once merged into an image claiming samples it did not have. Throws
/// lucent::Error naming `name`, the pixel (or the attribute) and the mismatch.
void check_counts(const std::string& name, const PartInfo& info, const Accumulation& a) {
  const std::uint64_t spp = total(info.samples);
  const std::string part_spp = std::to_string(spp) + " (samples " + ranges_text(info.samples) + ")";
  std::uint64_t missing = 0;  // samples the pixels so far miss
  for (size_t i = 0; i < a.count.size(); ++i) {
    if (a.count[i] > spp)
      throw Error(name + ": channel n: " + pixel_text(i, a.width) + " counts " +
                  std::to_string(a.count[i]) + " samples, more than the part's " + part_spp);
    missing += spp - a.count[i];
    if (missing > info.nonfinite)
      throw Error(name + ": channel n: " + pixel_text(i, a.width) + " counts " +
                  std::to_string(a.count[i]) + " samples of the part's " + part_spp +
                  (info.nonfinite == 0
                       ? ", and the part records no non-finite sample (lucent.nonfinite 0)"
                       : ": the pixels up to it miss " + std::to_string(missing) +
                             " samples, more than the " + std::to_string(info.nonfinite) +
                             " non-finite ones the part records (lucent.nonfinite)"));
  }
  if (missing != info.nonfinite)
    throw Error(name + ": attribute lucent.nonfinite: " + std::to_string(info.nonfinite) +
                " non-finite samples recorded, but the pixels (channel n) miss " +
                std::to_string(missing) + " of the part's " + part_spp + " per pixel");
}

/// What read_render_part takes back of a part's header and sums, for a part made in memory (a
/// library caller's, make_part's): write_render_part wrote headers and sums that reading then
/// refused, and a merger took a part whose own ranges overlapped, counting samples twice. Throws
/// lucent::Error naming `name`.
void check_part_contents(const std::string& name, const PartInfo& info, const Accumulation& a) {
  if (info.width <= 0 || info.height <= 0)
    throw Error(name + ": the part's film " + std::to_string(info.width) + "x" +
                std::to_string(info.height) + " has no pixels");
  for (const auto* list : {&info.samples, &info.requested})
    for (size_t k = 0; k < list->size(); ++k) {
      const SampleRange& r = (*list)[k];
      if (r.end <= r.begin || r.end > (1ull << 32) || (k > 0 && r.begin < (*list)[k - 1].end))
        throw Error(name + ": the part's " + (list == &info.samples ? "samples " : "requested ") +
                    ranges_text(*list) +
                    ": ranges must be non-empty, sorted, disjoint and end at 2^32 at most");
    }
  if (info.requested.empty()) throw Error(name + ": the part requests no sample range");
  if (unite(info.requested, info.samples) != info.requested)
    throw Error(name + ": the part's samples " + ranges_text(info.samples) +
                " lie outside the requested " + ranges_text(info.requested));
  if (!find_type<IntegratorType>(info.integrator))
    throw Error(name + ": the part's integrator '" + info.integrator + "' is unknown");
  if (!info.sampler.empty() && !find_type<SamplerType>(info.sampler))
    throw Error(name + ": the part's sampler '" + info.sampler + "' is unknown");
  if (!(info.seconds >= 0) || !std::isfinite(info.seconds))
    throw Error(name + ": the part's time must be a finite number of seconds >= 0");
  if (!(info.display.gamma > 0) || !std::isfinite(info.display.gamma) ||
      !std::isfinite(info.display.exposure))
    throw Error(name + ": the part's display gamma must be finite and > 0, its exposure finite");
  for (size_t i = 0; i < a.sum.size() && i < a.sumsq.size(); ++i)
    if (!std::isfinite(a.sum[i]) || !std::isfinite(a.sumsq[i]) || a.sumsq[i] < 0)
      throw Error(name + ": " + pixel_text(i / 3, std::max(a.width, 1)) +
                  " holds an invalid sum (not finite, or a negative sum of squares)");
  image_detail::check_sums_fit_float(name, a.width, a.sum, a.sumsq, a.count);
}

}  // namespace

std::string range_text(const SampleRange& r) {
  return "[" + std::to_string(r.begin) + ", " + std::to_string(r.end) + ")";
}

std::vector<SampleRange> missing_ranges(const std::vector<SampleRange>& have,
                                        const SampleRange& want) {
  std::vector<SampleRange> out;
  std::uint64_t at = want.begin;
  for (const SampleRange& s : have) {
    if (s.end <= at) continue;
    if (s.begin >= want.end) break;
    if (s.begin > at) out.push_back({at, s.begin});
    at = std::max(at, s.end);
  }
  if (at < want.end) out.push_back({at, want.end});
  return out;
}

std::string ranges_text(const std::vector<SampleRange>& rs) {
  if (rs.empty()) return "none";
  // a list of any length stays one readable line: the first ranges, the last, and the count
  constexpr size_t kListed = 8, kHead = 6;
  std::string out;
  const size_t head = rs.size() > kListed ? kHead : rs.size();
  for (size_t i = 0; i < head; ++i) out += (out.empty() ? "" : ", ") + range_text(rs[i]);
  if (head < rs.size())
    out += ", ..., " + range_text(rs.back()) + " (" + std::to_string(rs.size()) + " ranges)";
  return out;
}

SampleRange parse_sample_range(const std::string& text, const std::string& what, bool per_part) {
  const size_t colon = text.find(':');
  auto number = [&](const std::string& s, std::uint64_t* v) {
    // plain decimal, as the command line's integers ("010" read 10 where --spp 010 is refused)
    if (s.find_first_not_of("0123456789") != std::string::npos || !io::plain_decimal_integer(s) ||
        s.size() > 11)
      return false;
    *v = std::stoull(s);
    return true;
  };
  SampleRange r;
  if (colon == std::string::npos || !number(text.substr(0, colon), &r.begin) ||
      !number(text.substr(colon + 1), &r.end))
    throw Error(what + " '" + text + "': expected A:B, the sample indices [A, B) in decimal");
  if (r.end <= r.begin || r.end > (1ull << 32))
    throw Error(what + " '" + text + "': need 0 <= A < B <= 4294967296");
  if (per_part && r.end - r.begin > static_cast<std::uint64_t>(limits::kMaxSpp))
    throw Error(what + " '" + text + "': at most " + std::to_string(limits::kMaxSpp) +
                " samples per part");
  return r;
}

RenderResult part_result(const RenderPart& part) {
  const Accumulation& a = part.acc;
  if (!sums_fit_film(a))
    throw Error("part_result: inconsistent part (film and accumulation sizes differ)");
  RenderResult r;
  image_detail::part_image("part_result", a.width, a.height, a.sum, a.sumsq, a.count, r.mean,
                           r.variance);
  r.samples = a.count;
  r.spp = total(part.info.samples);
  r.seed = part.info.seed;
  r.sampler = part.info.sampler;
  r.nonfinite = part.info.nonfinite;
  r.rays = part.info.rays;
  r.seconds = part.info.seconds;
  return r;
}

namespace {

/// Refuses a PartCompression outside the enum (a cast integer), which was taken as zip.
void check_compression(const std::string& where, PartCompression compression) {
  if (compression != PartCompression::zip && compression != PartCompression::piz)
    throw Error(where + ": unknown part compression " +
                std::to_string(static_cast<int>(compression)) + " (zip or piz)");
}

}  // namespace

std::uint64_t part_write_bytes(int width, int height, PartCompression compression) {
  check_compression("part_write_bytes", compression);
  // (-1 x 5 was taken as 0 x 5: 1 MiB)
  if (width <= 0 || height <= 0)
    throw Error("part_write_bytes: the film size must be positive, got " + std::to_string(width) +
                "x" + std::to_string(height));
  const std::uint64_t npix = std::uint64_t(width) * std::uint64_t(height);
  // write_render_part's twelve 32-bit words and six float planes; the encoder's input is those
  // and the counts: 19 channels of 4 bytes. tinyexr's PIZ encoder holds, for each chunk of 32
  // lines beside its output, its input, twice its size of blocks and a temporary copy, and 2 MB
  // of Huffman tables: films of few lines (16384 x 32: about 200 MB) took more than the rest
  const std::uint64_t piz_chunk = std::uint64_t(width) * 32 * 19 * 4;
  return sys::bytes_add(
      sys::bytes_add(sys::bytes_mul(npix, 12 * sizeof(std::uint32_t) + 6 * sizeof(float)),
                     image_detail::exr_encoder_bytes(sys::bytes_mul(npix, 19 * 4))),
      compression == PartCompression::piz ? 4 * piz_chunk + (std::uint64_t(2) << 20) : 0);
}

void write_render_part(const std::string& path, const RenderPart& part,
                       PartCompression compression) {
  check_compression(path + ": cannot write part", compression);
  const PartInfo& info = part.info;
  const Accumulation& a = part.acc;
  if (a.width != info.width || a.height != info.height || !sums_fit_film(a))
    throw Error(path + ": cannot write part: inconsistent accumulation");
  if (a.light_paths > 0)
    throw Error(path +
                ": cannot write part: part files do not hold light-traced caustics "
                "(integrator.caustics); render the scene without --samples A:B");
  // what reading it back checks: a part made in memory wrote headers and sums that reading then
  // refused (a part of no samples, make_part's before a render, an attribute read back as a NUL)
  check_part_contents(path + ": cannot write part", info, a);
  if (info.samples.empty())
    throw Error(path + ": cannot write part: it holds no samples (render before make_part)");
  check_counts(path + ": cannot write part", info, a);
  parts_detail::write_part_unchecked(path, part, compression);
}

void parts_detail::write_part_unchecked(const std::string& path, const RenderPart& part,
                                        PartCompression compression) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  const PartInfo& info = part.info;
  const Accumulation& a = part.acc;
  const size_t npix = static_cast<size_t>(std::max(a.width, 0)) * std::max(a.height, 0);
  if (a.width != info.width || a.height != info.height || !sums_fit_film(a))
    throw Error(path + ": cannot write part: inconsistent accumulation");
  // each double as two UINT channels: its high and low 32 bits (EXR has no 64-bit pixel type);
  // one block for the twelve, and one for the mean and variance planes read_render shows, made
  // here from the sums (no RenderResult copy of the images)
  std::vector<std::uint32_t> words(12 * npix);
  std::vector<float> planes(6 * npix);
  image_detail::RenderPlanes shown;
  shown.width = a.width;
  shown.height = a.height;
  shown.samples = a.count.data();
  for (int c = 0; c < 3; ++c) {
    float* mean = planes.data() + size_t(c) * npix;
    float* var = planes.data() + size_t(3 + c) * npix;
    for (size_t i = 0; i < npix; ++i) {
      const double n = a.count[i], s = a.sum[i * 3 + c], s2 = a.sumsq[i * 3 + c];
      mean[i] = static_cast<float>(n > 0 ? s / n : 0);
      var[i] = static_cast<float>(render_detail::sample_variance(s, s2, n));
    }
    shown.mean[c] = mean;
    shown.variance[c] = var;
  }
  image_detail::ExrExtras extras;
  for (int plane = 0; plane < 2; ++plane) {
    const std::vector<double>& src = plane == 0 ? a.sum : a.sumsq;
    for (int c = 0; c < 3; ++c) {
      std::uint32_t* hi = words.data() + size_t(plane * 6 + c * 2) * npix;
      std::uint32_t* lo = hi + npix;
      for (size_t i = 0; i < npix; ++i) {
        std::uint64_t bits;
        std::memcpy(&bits, &src[i * 3 + c], sizeof bits);
        hi[i] = static_cast<std::uint32_t>(bits >> 32);
        lo[i] = static_cast<std::uint32_t>(bits);
      }
    }
  }
  for (int plane = 0, k = 0; plane < 2; ++plane)
    for (int c = 0; c < 3; ++c)
      for (bool high : {true, false})
        extras.uint_channels.emplace_back(channel_name(plane, c, high),
                                          words.data() + size_t(k++) * npix);
  // "%.6f" of any finite time: up to 309 digits before the point (DBL_MAX), the point and six
  // decimals (a buffer of 64 cut a time above 1e56 to its first 63 characters: 1e308, which
  // reading takes, was written as 1e62)
  char seconds[320];
  const std::string gamma = io::shortest_real(info.display.gamma),
                    exposure = io::shortest_real(info.display.exposure);
  std::snprintf(seconds, sizeof seconds, "%.6f", info.seconds);
  extras.attributes = {
      {"lucent.format", kFormat},
      {"lucent.film", std::to_string(info.width) + "x" + std::to_string(info.height)},
      {"lucent.hash", hex64(info.scene_hash)},
      {"lucent.seed", std::to_string(info.seed)},
      {"lucent.integrator", info.integrator},
      {"lucent.version", info.version},
      {"lucent.scene", info.scene},
      {"lucent.samples", ranges_attribute(info.samples)},
      {"lucent.requested", ranges_attribute(info.requested)},
      {"lucent.nonfinite", std::to_string(info.nonfinite)},
      {"lucent.rays", std::to_string(info.rays)},
      {"lucent.seconds", seconds},
      {"lucent.display", std::string(transfer_name(info.display.transfer)) + "," + gamma + "," +
                             exposure + "," + tonemap_name(info.display.tonemap)},
      {"lucent.checksum", hex64(sums_checksum(a))},
  };
  // read_render's seed and sampler (what converge checks a reference by)
  if (!info.sampler.empty()) extras.attributes.emplace_back("lucent.sampler", info.sampler);
  extras.piz = compression == PartCompression::piz;
  image_detail::write_render_planes(path, shown, extras);
}

namespace {

/// A part file is read whole: refused before reading when the file alone exceeds the memory
/// lucent allows itself (a regular file's size; read_file bounds the rest).
void check_part_file_size(const std::string& path) {
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  std::string what;
  const std::uint64_t limit = sys::host_memory_allowed(&what);
  if (!ec && limit > 0 && size > limit)
    throw Error(path + ": this part file (" + sys::format_bytes(size) +
                ") is larger than the memory limit of " + sys::format_bytes(limit) + " (80% of " +
                what + ")");
}

}  // namespace

PartInfo read_part_info(const std::string& path) {
  check_part_file_size(path);
  const std::string bytes = io::read_file(path, image_detail::part_read_spec());
  EXRHeader header;
  image_detail::Probe probe =
      image_detail::probe_exr(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(),
                              path, image_detail::kMaxImagePixels, header);
  const std::map<std::string, std::string> attrs = image_detail::exr_string_attributes(header);
  FreeEXRHeader(&header);
  return info_from_attributes(path, attrs, probe.width, probe.height);
}

namespace {

/// The part in `exr` (the channels and attributes of the part file `path`): its header, and its
/// sums, sums of squares and counts (checked against the checksum, and the counts against the
/// ranges).
RenderPart part_from_channels(const image_detail::ExrChannels& exr, const std::string& path) {
  RenderPart p;
  p.info = info_from_attributes(path, exr.attributes, exr.width, exr.height);
  image_detail::PartSums sums = image_detail::part_sums_from_channels(exr, path);
  Accumulation& a = p.acc;
  a.width = exr.width;
  a.height = exr.height;
  a.sum = std::move(sums.sum);
  a.sumsq = std::move(sums.sumsq);
  a.count = std::move(sums.count);
  check_counts(path, p.info, a);
  a.spp = total(p.info.samples);
  a.nonfinite = p.info.nonfinite;
  a.rays = p.info.rays;
  a.seconds = p.info.seconds;
  return p;
}

}  // namespace

RenderPart read_render_part(const std::string& path) {
  check_part_file_size(path);
  const std::string bytes = io::read_file(path, image_detail::part_read_spec());
  if (bytes.size() < 4 || std::memcmp(bytes.data(), "\x76\x2f\x31\x01", 4) != 0)
    throw Error(path + ": not a lucent part file (not an OpenEXR file)");
  {
    // what decoding takes, checked before it allocates, and the file itself
    EXRHeader header;
    image_detail::Probe probe =
        image_detail::probe_exr(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(),
                                path, image_detail::kMaxImagePixels, header);
    FreeEXRHeader(&header);
    image_detail::check_decode_memory(
        path, "part", probe, image_detail::exr_decode_bytes_per_pixel(probe), bytes.size());
  }
  const image_detail::ExrChannels exr =
      image_detail::read_exr_channels(reinterpret_cast<const unsigned char*>(bytes.data()),
                                      bytes.size(), path, image_detail::kMaxImagePixels);
  return part_from_channels(exr, path);
}

void PartMerger::check(const std::string& name, const PartInfo& info) {
  if (names_.empty()) return;
  const PartInfo& first = infos_.front();
  const std::string& fname = names_.front();
  if (info.width != first.width || info.height != first.height)
    throw Error(name + ": film " + std::to_string(info.width) + "x" + std::to_string(info.height) +
                " differs from " + fname + "'s " + std::to_string(first.width) + "x" +
                std::to_string(first.height));
  if (info.seed != first.seed)
    throw Error(name + ": seed " + std::to_string(info.seed) + " differs from " + fname + "'s " +
                std::to_string(first.seed));
  // (the scene hash covers the sampler too, but named it only as "another ... integrator
  // setting"; a part file of lucent before 24 Nov 2026 records none)
  if (!info.sampler.empty() && !first.sampler.empty() && info.sampler != first.sampler)
    throw Error(name + ": sampler " + info.sampler + " differs from " + fname + "'s " +
                first.sampler);
  if (info.integrator != first.integrator)
    throw Error(name + ": integrator " + info.integrator + " differs from " + fname + "'s " +
                first.integrator);
  if (info.version != first.version)
    throw Error(name + ": made by lucent " + info.version + ", " + fname + " by lucent " +
                first.version + " (their kernels may differ: render every part with one version)");
  if (info.scene_hash != first.scene_hash)
    throw Error(name + ": scene hash " + hex64(info.scene_hash) + " differs from " + fname + "'s " +
                hex64(first.scene_hash) +
                " (another scene, camera, film, integrator setting, build option or kernel "
                "source)");
  for (size_t k = 0; k < infos_.size(); ++k) {
    SampleRange a, b;
    if (overlap(info.samples, infos_[k].samples, &a, &b))
      throw Error(name + ": samples " + range_text(a) + " overlap " + names_[k] + "'s " +
                  range_text(b));
  }
}

void PartMerger::check_not_finished(const char* call) const {
  // (add() after finish() said "add() after add_header()", and finish() again "no parts added")
  if (finished_)
    throw Error(std::string("PartMerger: ") + call +
                " after finish(): a merger gives its merged part once (use a new one)");
}

void PartMerger::add_header(const std::string& name, const PartInfo& info) {
  check_not_finished("add_header()");
  // (after add(), a header was taken: its samples were then never added, and finish() said
  // "missing none")
  if (total_.info.width != 0)
    throw Error(name +
                ": PartMerger: add_header() after add(): a merger checks headers or adds "
                "parts, not both");
  check_part_contents(name, info, Accumulation{});
  check(name, info);
  names_.push_back(name);
  infos_.push_back(info);
}

void PartMerger::check_part(const std::string& name, const RenderPart& part) {
  check_not_finished("add()");
  // headers or parts, not both: after add_header there is no sum to add to (it read empty
  // vectors as a full film's)
  if (!names_.empty() && total_.info.width == 0)
    throw Error(name +
                ": PartMerger: add() after add_header(): a merger checks headers or adds "
                "parts, not both");
  const Accumulation& a = part.acc;
  check_part_contents(name, part.info, a);
  check(name, part.info);
  if (a.width <= 0 || a.height <= 0 || !sums_fit_film(a) || a.width != part.info.width ||
      a.height != part.info.height)
    throw Error(name + ": inconsistent part (film and accumulation sizes differ)");
  check_counts(name, part.info, a);  // a part of lucent-mpi's ranks, or of a library caller
}

void PartMerger::add(const std::string& name, RenderPart&& part) {
  if (!names_.empty()) return add(name, static_cast<const RenderPart&>(part));
  check_part(name, part);
  names_.push_back(name);
  infos_.push_back(part.info);
  total_ = std::move(part);
}

void PartMerger::add(const std::string& name, const RenderPart& part) {
  check_part(name, part);
  if (names_.empty()) {
    total_ = part;
  } else {
    const Accumulation& a = part.acc;
    const size_t npix = static_cast<size_t>(a.width) * a.height;
    Accumulation& t = total_.acc;
    for (size_t i = 0; i < npix; ++i)
      if (std::uint64_t(t.count[i]) + a.count[i] > 0xffffffffull)
        throw Error(name + ": pixel " + std::to_string(i % a.width) + ", " +
                    std::to_string(i / a.width) + ": more than 2^32 samples in all");
    // what only crafted parts reach, refused before the merge changes: sums past a double's
    // range, or a merged mean or variance past a float's (written as infinite), a time past a
    // double's (the output's writer refused it, naming the output), rays past 2^64 (wrapped)
    for (size_t i = 0; i < npix * 3; ++i) {
      const double s = t.sum[i] + a.sum[i], s2 = t.sumsq[i] + a.sumsq[i];
      if (!std::isfinite(s) || !std::isfinite(s2) ||
          !image_detail::sums_fit_float(s, s2, double(t.count[i / 3]) + a.count[i / 3]))
        throw Error(name + ": " + pixel_text(i / 3, a.width) +
                    ": merged with the parts before it, its mean or sample variance is beyond a "
                    "float's range (no render's is)");
    }
    if (!std::isfinite(total_.info.seconds + part.info.seconds))
      throw Error(name +
                  ": attribute lucent.seconds: the parts' times add up past a double's range");
    if (total_.info.rays + part.info.rays < total_.info.rays)
      throw Error(name + ": attribute lucent.rays: the parts' rays add up past 2^64");
    for (size_t i = 0; i < npix * 3; ++i) {
      t.sum[i] += a.sum[i];
      t.sumsq[i] += a.sumsq[i];
    }
    for (size_t i = 0; i < npix; ++i) t.count[i] += a.count[i];
    PartInfo& ti = total_.info;
    if (ti.sampler.empty()) ti.sampler = part.info.sampler;  // the same: the scene hash has it
    ti.samples = unite(ti.samples, part.info.samples);
    ti.requested = unite(ti.requested, part.info.requested);
    ti.nonfinite += part.info.nonfinite;
    ti.rays += part.info.rays;
    ti.seconds += part.info.seconds;
    t.spp = total(ti.samples);
    t.nonfinite = ti.nonfinite;
    t.rays = ti.rays;
    t.seconds = ti.seconds;
  }
  names_.push_back(name);
  infos_.push_back(part.info);
}

MergeReport PartMerger::finish() {
  check_not_finished("finish()");
  if (names_.empty()) throw Error("merge: no parts");
  if (total_.info.width == 0)
    throw Error("merge: no parts added (add_header() checks headers, add() adds parts)");
  MergeReport r;
  r.merged = std::move(total_);  // (not copied: a film's sums)
  total_ = RenderPart{};
  finished_ = true;
  r.order = names_;
  // missing: [0, the highest end requested) less what was rendered
  const std::uint64_t end =
      r.merged.info.requested.empty() ? 0 : r.merged.info.requested.back().end;
  std::uint64_t at = 0;
  for (const SampleRange& s : r.merged.info.samples) {
    if (s.begin > at) r.missing.push_back({at, s.begin});
    at = s.end;
  }
  if (at < end) r.missing.push_back({at, end});
  const std::vector<std::uint32_t>& count = r.merged.acc.count;
  if (!count.empty()) {
    r.min_spp = *std::min_element(count.begin(), count.end());
    r.max_spp = *std::max_element(count.begin(), count.end());
    double sum = 0;
    for (std::uint32_t n : count) sum += n;
    r.mean_spp = sum / double(count.size());
  }
  return r;
}

void check_merge_output(const std::string& output, const std::vector<std::string>& parts) {
  for (const std::string& in : parts)
    if (io::same_file(output, in))
      throw Error(output + ": is an input of the merge; refusing to overwrite it");
  // the format (.exr, .png, .pfm, as write_merged writes) and a place that can be written
  io::check_output_path(output, parts);
}

void check_merge_coverage(MergeReport& report, const std::optional<SampleRange>& expect,
                          bool complete, const std::string& expect_name,
                          const std::string& complete_name) {
  const std::vector<SampleRange>& samples = report.merged.info.samples;
  // as the command line's A:B: an inverted range ({8, 0}) was taken, and every sample was
  // "outside" it twice, below its begin and above its end ("[0, 4), [0, 4) outside [8, 0)")
  if (expect && (expect->end <= expect->begin || expect->end > (std::uint64_t(1) << 32)))
    throw Error("merge: " + expect_name + " " + range_text(*expect) +
                ": need 0 <= begin < end <= 4294967296");
  if (expect) {
    // the samples outside it (it named all of the parts' samples: "[0, 12)" for [0, 4))
    std::vector<SampleRange> outside;
    for (const SampleRange& s : samples) {
      if (s.begin < expect->begin) outside.push_back({s.begin, std::min(s.end, expect->begin)});
      if (s.end > expect->end) outside.push_back({std::max(s.begin, expect->end), s.end});
    }
    if (!outside.empty())
      throw Error("merge: the parts hold samples " + ranges_text(outside) + " outside " +
                  expect_name + " " + range_text(*expect) + " (they hold " + ranges_text(samples) +
                  ")");
    report.missing = missing_ranges(samples, *expect);
  }
  if (complete && !report.missing.empty())
    throw Error("merge: samples " + ranges_text(report.missing) + " are missing (" + complete_name +
                ")");
}

MergeReport merge_render_parts(const std::vector<std::string>& paths) {
  if (paths.empty()) throw Error("merge: no part files given");
  struct Entry {
    std::string path;
    PartInfo info;
  };
  std::vector<Entry> entries;
  PartMerger headers;  // every header is checked before any pixel is read
  // a file given twice, by its identity (links and copies of a name included): compared pairwise,
  // 4000 parts took 2 million stat calls and 31 s
  std::map<std::pair<dev_t, ino_t>, std::string> files;
  for (const std::string& p : paths) {
    struct stat st {};
    if (::stat(p.c_str(), &st) == 0) {
      const auto [it, fresh] = files.emplace(std::make_pair(st.st_dev, st.st_ino), p);
      if (!fresh) throw Error(p + ": given twice (as " + it->second + ")");
    }
    entries.push_back(Entry{p, read_part_info(p)});
    headers.add_header(p, entries.back().info);
  }
  std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    const std::uint64_t ka =
        a.info.samples.empty() ? a.info.requested.front().begin : a.info.samples.front().begin;
    const std::uint64_t kb =
        b.info.samples.empty() ? b.info.requested.front().begin : b.info.samples.front().begin;
    return ka < kb;
  });
  PartMerger merger;
  for (const Entry& e : entries) merger.add(e.path, read_render_part(e.path));
  return merger.finish();
}

void write_merged(const std::string& path, const RenderPart& part) {
  const std::string ext = io::lower_extension(path);
  if (ext == ".exr") {
    write_render_part(path, part);  // a part file keeps its counts, whatever they are
  } else if (ext == ".png" || ext == ".pfm") {
    render_detail::check_some_sample_finite(path, part.info.nonfinite, part.acc.count);
    write_image(path, part_result(part).mean, part.info.display);
  } else {
    io::unknown_output_format(path, ext, ".exr, .png or .pfm");
  }
}

}  // namespace lucent
