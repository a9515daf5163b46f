// Renders with their statistics: an OpenEXR file with the mean (R, G, B), the per-pixel sample
// variance (var.R, var.G, var.B) and the per-pixel finite-sample count (n), through tinyexr.
// Format: docs/compare.md.
#include <tinyexr.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/file_io.hpp"
#include "core/host_memory.hpp"
#include "core/text.hpp"
#include "image/image_probe.hpp"
#include "image/part_sums.hpp"
#include "lucent/compare.hpp"
#include "lucent/error.hpp"
#include "lucent/image.hpp"

namespace lucent {

void write_render_exr(const std::string& path, const RenderResult& r) {
  image_detail::ExrExtras extras;
  if (!r.sampler.empty())
    extras.attributes = {{"lucent.seed", std::to_string(r.seed)}, {"lucent.sampler", r.sampler}};
  if (r.light_mean_variance) {
    // what read_render takes back (a NaN was written, and the file then refused)
    const std::string attribute = image_detail::light_mean_var_attribute(*r.light_mean_variance);
    image_detail::parse_light_mean_var(path + ": cannot write EXR", attribute);
    extras.attributes.emplace_back("lucent.light_mean_var", attribute);
  }
  image_detail::write_render_exr(path, r, extras);
}

namespace image_detail {

std::string light_mean_var_attribute(const LightMeanVariance& v) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  std::string s;
  char buf[32];
  for (const double* part : {v.paths, v.pixels})
    for (int c = 0; c < 3; ++c) {
      std::snprintf(buf, sizeof buf, "%.17g", part[c]);
      s += (s.empty() ? "" : " ") + std::string(buf);
    }
  return s;
}

LightMeanVariance parse_light_mean_var(const std::string& path, const std::string& text) {
  io::CNumbers c_numbers;  // "0.5", whatever the process locale
  LightMeanVariance v;
  double* const values[6] = {&v.paths[0],  &v.paths[1],  &v.paths[2],
                             &v.pixels[0], &v.pixels[1], &v.pixels[2]};
  const char* p = text.c_str();
  int k = 0;
  for (; k < 6; ++k) {
    char* end = nullptr;
    const double x = std::strtod(p, &end);
    if (end == p || (*end != ' ' && *end != '\0') || !(x >= 0) || !std::isfinite(x)) break;
    *values[k] = x;
    p = end;
  }
  while (*p == ' ') ++p;
  if (k == 6 && *p == '\0') return v;
  std::string shown = text.substr(0, 80) + (text.size() > 80 ? "..." : "");
  for (char& ch : shown)
    if (static_cast<unsigned char>(ch) < 0x20) ch = '?';  // one line
  throw Error(path +
              ": attribute lucent.light_mean_var: expected 6 finite numbers >= 0 (the image "
              "mean's light-path and per-pixel light variances, R G B each), got '" +
              shown + "'");
}

void write_render_exr(const std::string& path, const RenderResult& r, const ExrExtras& extras) {
  const size_t n = static_cast<size_t>(r.mean.width) * r.mean.height;
  if (r.mean.rgb.size() != n * 3) throw Error(path + ": cannot write EXR: inconsistent image");
  // a layer that is there has the image's size (layers of another size were left out without a
  // word: a file meant to carry them came out with the mean alone), and a variance its counts.
  // Counts without a variance (Python's RenderResult(mean, samples=...)) are no statistics: the
  // mean alone is written, as before.
  if ((!r.variance.rgb.empty() && (r.variance.rgb.size() != n * 3 || r.samples.size() != n)) ||
      (!r.samples.empty() && r.samples.size() != n))
    throw Error(path + ": cannot write EXR: the variance layer has " +
                std::to_string(r.variance.rgb.size()) + " values and the sample counts " +
                std::to_string(r.samples.size()) + ", where a " + std::to_string(r.mean.width) +
                "x" + std::to_string(r.mean.height) + " image has " + std::to_string(n * 3) +
                " and " + std::to_string(n) + " (a variance needs the counts)");
  const bool stats = !r.variance.rgb.empty();
  write_image_exr(path, r.mean, stats ? &r.variance : nullptr, stats ? r.samples.data() : nullptr,
                  extras);
}

void write_image_exr(const std::string& path, const Image& mean, const Image* variance,
                     const std::uint32_t* samples, const ExrExtras& extras) {
  const size_t n = static_cast<size_t>(mean.width) * mean.height;
  const bool stats = variance && samples;
  // the images are interleaved RGB; EXR's channels are planes
  std::vector<float> planes((stats ? 6 : 3) * n);
  RenderPlanes p;
  p.width = mean.width;
  p.height = mean.height;
  for (int c = 0; c < 3; ++c) {
    float* m = planes.data() + size_t(c) * n;
    for (size_t i = 0; i < n; ++i) m[i] = mean.rgb[i * 3 + c];
    p.mean[c] = m;
    if (!stats) continue;
    float* var = planes.data() + size_t(3 + c) * n;
    for (size_t i = 0; i < n; ++i) var[i] = variance->rgb[i * 3 + c];
    p.variance[c] = var;
  }
  if (stats) p.samples = samples;
  write_render_planes(path, p, extras);
}

std::uint64_t render_exr_write_bytes(int width, int height, bool stats, int extra_uint_channels) {
  const std::uint64_t npix = std::uint64_t(std::max(width, 0)) * std::uint64_t(std::max(height, 0));
  const std::uint64_t floats = stats ? 6 : 3;
  const std::uint64_t channels = floats + (stats ? 1 : 0) + std::uint64_t(extra_uint_channels);
  return sys::bytes_add(sys::bytes_mul(npix, floats * sizeof(float)),
                        exr_encoder_bytes(sys::bytes_mul(npix, channels * 4)));
}

void write_render_planes(const std::string& path, const RenderPlanes& r, const ExrExtras& extras) {
  const int w = r.width, h = r.height;
  const size_t n = static_cast<size_t>(std::max(w, 0)) * static_cast<size_t>(std::max(h, 0));
  // (a 0x0 image made a file that read_render refused: "empty data window")
  if (n == 0) throw Error(path + ": cannot write EXR: the image has no pixels");
  for (const float* m : r.mean)
    if (!m) throw Error(path + ": cannot write EXR: inconsistent image");
  const bool stats = r.samples && r.variance[0] && r.variance[1] && r.variance[2];
  struct Channel {
    std::string name;
    unsigned char* data;
    int type;
  };
  auto bytes = [](const void* data) {
    return reinterpret_cast<unsigned char*>(const_cast<void*>(data));
  };
  // the mean, then the statistics and the extras, sorted below
  std::vector<Channel> channels = {{"R", bytes(r.mean[0]), TINYEXR_PIXELTYPE_FLOAT},
                                   {"G", bytes(r.mean[1]), TINYEXR_PIXELTYPE_FLOAT},
                                   {"B", bytes(r.mean[2]), TINYEXR_PIXELTYPE_FLOAT}};
  if (stats)
    channels.insert(channels.end(), {{"n", bytes(r.samples), TINYEXR_PIXELTYPE_UINT},
                                     {"var.R", bytes(r.variance[0]), TINYEXR_PIXELTYPE_FLOAT},
                                     {"var.G", bytes(r.variance[1]), TINYEXR_PIXELTYPE_FLOAT},
                                     {"var.B", bytes(r.variance[2]), TINYEXR_PIXELTYPE_FLOAT}});
  for (const auto& [name, data] : extras.uint_channels)
    channels.push_back({name, bytes(data), TINYEXR_PIXELTYPE_UINT});
  // OpenEXR wants the channels sorted by name
  std::sort(channels.begin(), channels.end(),
            [](const Channel& a, const Channel& b) { return a.name < b.name; });
  const int nch = static_cast<int>(channels.size());
  std::vector<unsigned char*> ptrs;
  std::vector<int> types;
  std::vector<EXRChannelInfo> infos(nch);
  for (int k = 0; k < nch; ++k) {
    ptrs.push_back(channels[k].data);
    types.push_back(channels[k].type);
    std::memset(&infos[k], 0, sizeof(EXRChannelInfo));
    std::strncpy(infos[k].name, channels[k].name.c_str(), 255);
  }
  std::vector<EXRAttribute> attributes(extras.attributes.size());
  for (size_t k = 0; k < attributes.size(); ++k) {
    std::memset(&attributes[k], 0, sizeof(EXRAttribute));
    std::strncpy(attributes[k].name, extras.attributes[k].first.c_str(), 255);
    std::strncpy(attributes[k].type, "string", 255);
    attributes[k].value =
        reinterpret_cast<unsigned char*>(const_cast<char*>(extras.attributes[k].second.data()));
    attributes[k].size = static_cast<int>(extras.attributes[k].second.size());
  }
  EXRHeader header;
  InitEXRHeader(&header);
  EXRImage image;
  InitEXRImage(&image);
  image.images = ptrs.data();
  image.num_channels = nch;
  image.width = w;
  image.height = h;
  header.num_channels = nch;
  header.channels = infos.data();
  header.pixel_types = types.data();
  header.requested_pixel_types = types.data();
  header.compression_type = extras.piz ? TINYEXR_COMPRESSIONTYPE_PIZ : TINYEXR_COMPRESSIONTYPE_ZIP;
  header.num_custom_attributes = static_cast<int>(attributes.size());
  header.custom_attributes = attributes.empty() ? nullptr : attributes.data();
  write_exr(path, image, header);
}

}  // namespace image_detail

RenderResult read_render(const std::string& path) {
  return image_detail::read_render(path, nullptr);
}

namespace image_detail {

RenderResult read_render_memory(const unsigned char* data, std::size_t size,
                                const std::string& path) {
  RenderResult r;
  if (size < 4 || std::memcmp(data, "\x76\x2f\x31\x01", 4) != 0) {
    Decoded d = decode_image(data, size, path, 3, kMaxImagePixels);
    r.mean = Image{d.width, d.height, std::move(d.pixels)};
    return r;
  }
  ExrChannels exr = read_exr_channels(data, size, path, kMaxImagePixels);
  const int rgb[3] = {exr.find("R"), exr.find("G"), exr.find("B")};
  if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) {
    // not our layout (a luminance-only EXR, or one of some of R, G and B, say): the general
    // reader makes it grey, fills the missing colour channels with 0, or refuses
    // (its channels go first: the memory check counted one decoding, not two at once)
    exr = ExrChannels{};
    Decoded d = decode_image(data, size, path, 3, kMaxImagePixels);
    r.mean = Image{d.width, d.height, std::move(d.pixels)};
    return r;
  }
  const int w = exr.width, h = exr.height;
  const size_t n = static_cast<size_t>(w) * h;
  // a part file (a checkpoint, a --samples part) with a checksum: its image from its sums, which
  // the checksum covers, not from its display channels, which it does not (a damaged PIZ chunk
  // of a checkpoint read as a mean of 1.5e24, which compare reported as a difference). The same
  // values for an intact file: the display channels are written from the sums.
  const bool part = exr.attributes.count("lucent.checksum") > 0;
  // the key of its random numbers, when a lucent render wrote it (write_render_exr)
  auto seed = exr.attributes.find("lucent.seed"), sampler = exr.attributes.find("lucent.sampler");
  if (seed != exr.attributes.end() && sampler != exr.attributes.end()) {
    r.seed = static_cast<std::uint32_t>(
        parse_attribute_u64(path, "lucent.seed", seed->second, 0xffffffffu));
    r.sampler = sampler->second;
  }
  // caustics: the image mean's light part (RenderResult::light_mean_variance)
  auto light = exr.attributes.find("lucent.light_mean_var");
  if (light != exr.attributes.end())
    r.light_mean_variance = parse_light_mean_var(path, light->second);
  if (part) {
    // mean and variance as write_render_part wrote them from the sums (part_result's)
    PartSums s = part_sums_from_channels(exr, path);
    part_image(path, w, h, s.sum, s.sumsq, s.count, r.mean, r.variance);
    r.samples = std::move(s.count);
    r.spp = r.samples.empty() ? 0 : *std::max_element(r.samples.begin(), r.samples.end());
    return r;
  }
  r.mean = Image{w, h, std::vector<float>(n * 3)};
  for (int c = 0; c < 3; ++c)
    for (size_t i = 0; i < n; ++i) r.mean.rgb[i * 3 + c] = exr.planes[rgb[c]][i];
  const int var[3] = {exr.find("var.R"), exr.find("var.G"), exr.find("var.B")};
  const int cnt = exr.find("n");
  const int stats = (var[0] >= 0) + (var[1] >= 0) + (var[2] >= 0) + (cnt >= 0);
  if (stats == 0) return r;
  // some of the layers alone: their variances were dropped without a word, and a noisy image
  // was compared as an exact one (a tolerance test, which it failed)
  if (stats < 4) {
    std::string missing;
    for (const char* name : {"var.R", "var.G", "var.B", "n"})
      if (exr.find(name) < 0) missing += std::string(missing.empty() ? "" : ", ") + name;
    throw Error(path + ": has some of the statistics channels var.R, var.G, var.B and n, not " +
                missing + " (a variance per sample needs its count, n): write all four, or none");
  }
  r.variance = Image{w, h, std::vector<float>(n * 3)};
  for (int c = 0; c < 3; ++c)
    for (size_t i = 0; i < n; ++i) r.variance.rgb[i * 3 + c] = exr.planes[var[c]][i];
  r.samples.resize(n);
  std::uint32_t most = 0;
  // lucent writes n as UINT: read it exactly (its float copy rounds counts above 2^24, which
  // merged parts reach: 16777217 read back as 16777216)
  const bool exact = exr.uint_planes[cnt].size() == n;
  for (size_t i = 0; i < n; ++i) {
    if (exact) {
      r.samples[i] = exr.uint_planes[cnt][i];
    } else {
      // a count is a non-negative integer: anything else (NaN, negative, huge) is a corrupt file
      const float v = exr.planes[cnt][i];
      if (!(v >= 0.0f && v < 4294967296.0f) || v != std::floor(v))
        throw Error(path + ": channel n: pixel " + std::to_string(i % w) + ", " +
                    std::to_string(i / w) + " has an invalid sample count " + std::to_string(v));
      r.samples[i] = static_cast<std::uint32_t>(v);
    }
    most = std::max(most, r.samples[i]);
  }
  r.spp = most;
  return r;
}

RenderResult read_render(const std::string& path, Format* format) {
  const std::string bytes = io::read_file(path, image_read_spec());
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const Probe p = probe_image(data, bytes.size(), path, kMaxImagePixels);
  if (format) *format = p.format;
  // decoding holds the file and, per pixel, the decoded planes and the result's images: for an
  // OpenEXR by its channels (exr_decode_bytes_per_pixel), 32 bytes for the others (two
  // 16384x16384 PNGs took 9.4 GB in compare)
  check_decode_memory(path, "image", p,
                      p.format == Format::Exr ? exr_decode_bytes_per_pixel(p) : 32, bytes.size());
  return read_render_memory(data, bytes.size(), path);
}

std::uint64_t parse_attribute_u64(const std::string& path, const std::string& what,
                                  const std::string& s, std::uint64_t max) {
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
  if (s.empty() || s[0] < '0' || s[0] > '9' || *end != '\0' || errno == ERANGE || v > max)
    throw Error(path + ": attribute " + what + ": invalid number '" + s + "'");
  return v;
}

}  // namespace image_detail

}  // namespace lucent
