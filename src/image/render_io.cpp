// Renders with their statistics: an OpenEXR file with the mean (R, G, B), the per-pixel sample
// variance (var.R, var.G, var.B) and the per-pixel finite-sample count (n), through tinyexr.
// Format: docs/compare.md.
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <tinyexr.h>

#include "lucent/compare.hpp"
#include "lucent/error.hpp"
#include "lucent/image.hpp"

namespace lucent {

namespace {

std::string exr_message(const char* err) {
  std::string msg = err ? err : "unknown error";
  if (err) FreeEXRErrorMessage(err);
  return msg;
}

}  // namespace

void write_render_exr(const std::string& path, const RenderResult& r) {
  const int w = r.mean.width, h = r.mean.height;
  const size_t n = static_cast<size_t>(w) * h;
  if (r.mean.rgb.size() != n * 3) throw Error(path + ": cannot write EXR: inconsistent image");
  const bool stats = r.variance.rgb.size() == n * 3 && r.samples.size() == n;
  // channels in the sorted order OpenEXR wants: B G R n var.B var.G var.R
  std::vector<std::string> names = {"B", "G", "R"};
  std::vector<std::vector<float>> planes;
  for (int c = 2; c >= 0; --c) {
    planes.emplace_back(n);
    for (size_t i = 0; i < n; ++i) planes.back()[i] = r.mean.rgb[i * 3 + c];
  }
  std::vector<unsigned int> counts;
  if (stats) {
    names.insert(names.end(), {"n", "var.B", "var.G", "var.R"});
    counts.assign(r.samples.begin(), r.samples.end());
    for (int c = 2; c >= 0; --c) {
      planes.emplace_back(n);
      for (size_t i = 0; i < n; ++i) planes.back()[i] = r.variance.rgb[i * 3 + c];
    }
  }
  const int nch = static_cast<int>(names.size());
  std::vector<unsigned char*> ptrs;
  std::vector<int> types;
  for (int k = 0, p = 0; k < nch; ++k) {
    if (names[k] == "n") {
      ptrs.push_back(reinterpret_cast<unsigned char*>(counts.data()));
      types.push_back(TINYEXR_PIXELTYPE_UINT);
    } else {
      ptrs.push_back(reinterpret_cast<unsigned char*>(planes[p++].data()));
      types.push_back(TINYEXR_PIXELTYPE_FLOAT);
    }
  }
  std::vector<EXRChannelInfo> infos(nch);
  for (int k = 0; k < nch; ++k) {
    std::memset(&infos[k], 0, sizeof(EXRChannelInfo));
    std::strncpy(infos[k].name, names[k].c_str(), 255);
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
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
  const char* err = nullptr;
  if (SaveEXRImageToFile(&image, &header, path.c_str(), &err) != TINYEXR_SUCCESS)
    throw Error(path + ": cannot write EXR: " + exr_message(err));
}

RenderResult read_render(const std::string& path) {
  RenderResult r;
  auto ext_is_exr = [&]() {
    auto dot = path.find_last_of('.');
    if (dot == std::string::npos) return false;
    std::string e = path.substr(dot + 1);
    for (auto& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return e == "exr";
  };
  if (!ext_is_exr()) {
    r.mean = read_image(path);
    return r;
  }
  EXRVersion version;
  if (ParseEXRVersionFromFile(&version, path.c_str()) != TINYEXR_SUCCESS)
    throw Error(path + ": cannot read EXR: not an OpenEXR file or unreadable");
  if (version.multipart || version.non_image || version.tiled) {
    r.mean = read_image(path);  // not our layout: plain colour only
    return r;
  }
  EXRHeader header;
  InitEXRHeader(&header);
  const char* err = nullptr;
  if (ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err) != TINYEXR_SUCCESS)
    throw Error(path + ": cannot read EXR header: " + exr_message(err));
  for (int k = 0; k < header.num_channels; ++k)
    if (header.pixel_types[k] == TINYEXR_PIXELTYPE_HALF)
      header.requested_pixel_types[k] = TINYEXR_PIXELTYPE_FLOAT;
  EXRImage image;
  InitEXRImage(&image);
  if (LoadEXRImageFromFile(&image, &header, path.c_str(), &err) != TINYEXR_SUCCESS) {
    FreeEXRHeader(&header);
    throw Error(path + ": cannot read EXR: " + exr_message(err));
  }
  auto find = [&](const char* name) {
    for (int k = 0; k < header.num_channels; ++k)
      if (std::strcmp(header.channels[k].name, name) == 0) return k;
    return -1;
  };
  int rgb[3] = {find("R"), find("G"), find("B")};
  int var[3] = {find("var.R"), find("var.G"), find("var.B")};
  int cnt = find("n");
  const int w = image.width, h = image.height;
  const size_t n = static_cast<size_t>(w) * h;
  bool ok = rgb[0] >= 0 && rgb[1] >= 0 && rgb[2] >= 0 && image.images != nullptr;
  for (int c = 0; c < 3 && ok; ++c)
    if (header.requested_pixel_types[rgb[c]] != TINYEXR_PIXELTYPE_FLOAT) ok = false;
  if (ok) {
    r.mean = Image{w, h, std::vector<float>(n * 3)};
    for (int c = 0; c < 3; ++c) {
      const float* src = reinterpret_cast<const float*>(image.images[rgb[c]]);
      for (size_t i = 0; i < n; ++i) r.mean.rgb[i * 3 + c] = src[i];
    }
    bool stats = var[0] >= 0 && var[1] >= 0 && var[2] >= 0 && cnt >= 0;
    for (int c = 0; c < 3 && stats; ++c)
      if (header.requested_pixel_types[var[c]] != TINYEXR_PIXELTYPE_FLOAT) stats = false;
    if (stats) {
      r.variance = Image{w, h, std::vector<float>(n * 3)};
      for (int c = 0; c < 3; ++c) {
        const float* src = reinterpret_cast<const float*>(image.images[var[c]]);
        for (size_t i = 0; i < n; ++i) r.variance.rgb[i * 3 + c] = src[i];
      }
      r.samples.resize(n);
      int t = header.requested_pixel_types[cnt];
      for (size_t i = 0; i < n; ++i) {
        if (t == TINYEXR_PIXELTYPE_UINT)
          r.samples[i] = reinterpret_cast<const unsigned int*>(image.images[cnt])[i];
        else
          r.samples[i] = static_cast<std::uint32_t>(reinterpret_cast<const float*>(image.images[cnt])[i]);
      }
      std::uint32_t most = 0;
      for (auto s : r.samples) most = std::max(most, s);
      r.spp = most;
    }
  }
  FreeEXRImage(&image);
  FreeEXRHeader(&header);
  if (!ok) r.mean = read_image(path);  // e.g. a luminance-only EXR: let the general reader try
  return r;
}

}  // namespace lucent
