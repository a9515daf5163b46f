// Image output and input: PNG/JPG/BMP/TGA through stb, PFM by hand (a trivial format), EXR
// through tinyexr.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <tinyexr.h>

#include "lucent/error.hpp"
#include "lucent/image.hpp"

namespace lucent {

namespace {

std::string extension(const std::string& path) {
  auto dot = path.find_last_of('.');
  auto slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

double tonemap(double v, ToneMap t) {
  switch (t) {
    case ToneMap::Reinhard:
      return v / (1.0 + v);
    case ToneMap::Aces: {
      // Narkowicz 2015 fit of the ACES filmic curve
      const double a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
      return (v * (a * v + b)) / (v * (c * v + d) + e);
    }
    default:
      return v;
  }
}

std::string io_error(const std::string& path, const std::string& what) {
  std::string msg = path + ": " + what;
  if (errno) msg += " (" + std::string(std::strerror(errno)) + ")";
  return msg;
}

void write_pfm(const std::string& path, const Image& img) {
  errno = 0;
  std::ofstream f(path, std::ios::binary);
  if (!f) throw Error(io_error(path, "cannot open for writing"));
  f << "PF\n" << img.width << " " << img.height << "\n-1.0\n";  // negative scale: little endian
  // PFM stores rows bottom to top
  for (int y = img.height - 1; y >= 0; --y)
    f.write(reinterpret_cast<const char*>(img.pixel(0, y)),
            static_cast<std::streamsize>(sizeof(float) * 3 * img.width));
  if (!f) throw Error(io_error(path, "write failed"));
}

Image read_pfm(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw Error(path + ": cannot open image");
  std::string magic;
  int w = 0, h = 0;
  double scale = 0;
  f >> magic >> w >> h >> scale;
  f.get();
  if ((magic != "PF" && magic != "Pf") || w <= 0 || h <= 0 || scale == 0 || !f)
    throw Error(path + ": not a valid PFM header");
  if (scale > 0) throw Error(path + ": big-endian PFM is not supported");
  int channels = magic == "PF" ? 3 : 1;
  std::vector<float> raw(static_cast<size_t>(w) * h * channels);
  f.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(raw.size() * sizeof(float)));
  if (!f) throw Error(path + ": truncated PFM data");
  Image img{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        img.pixel(x, h - 1 - y)[c] = raw[(static_cast<size_t>(y) * w + x) * channels + (channels == 3 ? c : 0)];
  return img;
}

void write_exr(const std::string& path, const Image& img) {
  // tinyexr wants planar channels in B, G, R order
  EXRHeader header;
  InitEXRHeader(&header);
  EXRImage image;
  InitEXRImage(&image);
  size_t n = static_cast<size_t>(img.width) * img.height;
  std::vector<float> planes[3];
  for (int c = 0; c < 3; ++c) {
    planes[c].resize(n);
    for (size_t i = 0; i < n; ++i) planes[c][i] = img.rgb[i * 3 + c];
  }
  float* ptrs[3] = {planes[2].data(), planes[1].data(), planes[0].data()};
  image.images = reinterpret_cast<unsigned char**>(ptrs);
  image.num_channels = 3;
  image.width = img.width;
  image.height = img.height;
  header.num_channels = 3;
  std::vector<EXRChannelInfo> infos(3);
  const char* names[3] = {"B", "G", "R"};
  for (int c = 0; c < 3; ++c) {
    std::strncpy(infos[c].name, names[c], 255);
    infos[c].name[255] = '\0';
  }
  header.channels = infos.data();
  std::vector<int> types(3, TINYEXR_PIXELTYPE_FLOAT);
  header.pixel_types = types.data();
  header.requested_pixel_types = types.data();
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
  const char* err = nullptr;
  errno = 0;
  int rc = SaveEXRImageToFile(&image, &header, path.c_str(), &err);
  if (rc != TINYEXR_SUCCESS) {
    std::string msg = err ? err : "unknown error";
    if (err) FreeEXRErrorMessage(err);
    throw Error(path + ": cannot write EXR: " + msg);
  }
}

Image read_exr(const std::string& path) {
  float* data = nullptr;
  int w = 0, h = 0;
  const char* err = nullptr;
  int rc = LoadEXR(&data, &w, &h, path.c_str(), &err);
  if (rc != TINYEXR_SUCCESS) {
    std::string msg = err ? err : "unknown error";
    if (err) FreeEXRErrorMessage(err);
    throw Error(path + ": cannot read EXR: " + msg);
  }
  Image img{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i)
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = data[i * 4 + c];
  std::free(data);
  return img;
}

double srgb_to_linear(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

}  // namespace

unsigned char encode_display(double v, const DisplaySettings& d) {
  if (!std::isfinite(v)) v = 0;  // NaN/Inf never reach the film; guard the encoder anyway
  v *= std::exp2(d.exposure);
  v = tonemap(std::max(0.0, v), d.tonemap);
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

void write_image(const std::string& path, const Image& img, const DisplaySettings& display) {
  if (img.width <= 0 || img.height <= 0 ||
      img.rgb.size() != static_cast<size_t>(img.width) * img.height * 3)
    throw Error(path + ": refusing to write an empty or inconsistent image");
  std::string ext = extension(path);
  if (ext == "pfm") return write_pfm(path, img);
  if (ext == "exr") return write_exr(path, img);
  if (ext == "png") {
    std::vector<unsigned char> bytes(img.rgb.size());
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = encode_display(img.rgb[i], display);
    errno = 0;
    if (!stbi_write_png(path.c_str(), img.width, img.height, 3, bytes.data(), img.width * 3))
      throw Error(io_error(path, "cannot write PNG"));
    return;
  }
  throw Error(path + ": unknown output format '." + ext + "' (use .png, .pfm or .exr)");
}

Image read_image(const std::string& path) {
  std::string ext = extension(path);
  if (ext == "pfm") return read_pfm(path);
  if (ext == "exr") return read_exr(path);
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 3);
  if (!data) throw Error(path + ": cannot read image: " + std::string(stbi_failure_reason()));
  Image img{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = static_cast<float>(srgb_to_linear(data[i] / 255.0));
  stbi_image_free(data);
  return img;
}

}  // namespace lucent
