#include "image/part_sums.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "lucent/error.hpp"
#include "render/sample_stats.hpp"

namespace lucent::image_detail {

namespace {
constexpr const char* kPlanes[2] = {"sum", "sumsq"};
constexpr const char* kRgb[3] = {"R", "G", "B"};
}  // namespace

std::string part_channel_name(int plane, int c, bool high) {
  return std::string(kPlanes[plane]) + "." + kRgb[c] + (high ? ".hi" : ".lo");
}

std::uint64_t part_sums_checksum(const std::vector<double>& sum, const std::vector<double>& sumsq,
                                 const std::vector<std::uint32_t>& count) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  auto mix = [&h](std::uint64_t w) {
    h = (h ^ w) * 0x100000001b3ull;
    h ^= h >> 29;
  };
  for (const std::vector<double>* v : {&sum, &sumsq})
    for (const double d : *v) {
      std::uint64_t bits;
      std::memcpy(&bits, &d, sizeof bits);
      mix(bits);
    }
  for (const std::uint32_t n : count) mix(n);
  return h;
}

std::string hex64(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
  return buf;
}

bool sums_fit_float(double sum, double sumsq, double n) {
  const double mean = n > 0 ? sum / n : 0;
  return std::isfinite(static_cast<float>(mean)) &&
         std::isfinite(static_cast<float>(render_detail::sample_variance(sum, sumsq, n)));
}

void check_sums_fit_float(const std::string& name, int width, const std::vector<double>& sum,
                          const std::vector<double>& sumsq,
                          const std::vector<std::uint32_t>& count) {
  const size_t w = static_cast<size_t>(std::max(width, 1));
  for (size_t i = 0; i < sum.size() && i < sumsq.size() && i / 3 < count.size(); ++i)
    if (!sums_fit_float(sum[i], sumsq[i], count[i / 3]))
      throw Error(name + ": pixel " + std::to_string(i / 3 % w) + ", " + std::to_string(i / 3 / w) +
                  ": its mean or sample variance is beyond a float's range (no render's is)");
}

void part_image(const std::string& name, int width, int height, const std::vector<double>& sum,
                const std::vector<double>& sumsq, const std::vector<std::uint32_t>& count,
                Image& mean, Image& variance) {
  check_sums_fit_float(name, width, sum, sumsq, count);
  const size_t npix = static_cast<size_t>(width) * height;
  mean = Image{width, height, std::vector<float>(npix * 3)};
  variance = Image{width, height, std::vector<float>(npix * 3)};
  for (size_t i = 0; i < npix; ++i) {
    const double n = count[i];
    for (int c = 0; c < 3; ++c) {
      const double s = sum[i * 3 + c], s2 = sumsq[i * 3 + c];
      mean.rgb[i * 3 + c] = static_cast<float>(n > 0 ? s / n : 0);
      variance.rgb[i * 3 + c] = static_cast<float>(render_detail::sample_variance(s, s2, n));
    }
  }
}

PartSums part_sums_from_channels(const ExrChannels& exr, const std::string& path) {
  const size_t npix = static_cast<size_t>(exr.width) * exr.height;
  PartSums p;
  p.sum.resize(npix * 3);
  p.sumsq.resize(npix * 3);
  auto uint_channel = [&](const std::string& name) -> const std::vector<std::uint32_t>& {
    const int k = exr.find(name.c_str());
    if (k < 0 || exr.uint_planes[k].size() != npix)
      throw Error(path + ": part file has no UINT channel " + name);
    return exr.uint_planes[k];
  };
  for (int plane = 0; plane < 2; ++plane) {
    std::vector<double>& dst = plane == 0 ? p.sum : p.sumsq;
    for (int c = 0; c < 3; ++c) {
      const std::vector<std::uint32_t>& hi = uint_channel(part_channel_name(plane, c, true));
      const std::vector<std::uint32_t>& lo = uint_channel(part_channel_name(plane, c, false));
      for (size_t i = 0; i < npix; ++i) {
        const std::uint64_t bits = (std::uint64_t(hi[i]) << 32) | lo[i];
        std::memcpy(&dst[i * 3 + c], &bits, sizeof(double));
        if (!std::isfinite(dst[i * 3 + c]) || (plane == 1 && dst[i * 3 + c] < 0))
          throw Error(path + ": channel " + part_channel_name(plane, c, true) + ": pixel " +
                      std::to_string(i % exr.width) + ", " + std::to_string(i / exr.width) +
                      " holds an invalid sum");
      }
    }
  }
  p.count = uint_channel("n");
  if (auto sum = exr.attributes.find("lucent.checksum");
      sum != exr.attributes.end() &&
      sum->second != hex64(part_sums_checksum(p.sum, p.sumsq, p.count)))
    throw Error(path + ": part file is damaged: its samples do not match its checksum");
  // a mean or variance no render has, that a float image would show as infinite (a crafted file)
  check_sums_fit_float(path, exr.width, p.sum, p.sumsq, p.count);
  return p;
}

}  // namespace lucent::image_detail
