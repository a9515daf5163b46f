// Seed corpora for the fuzz targets, generated from the project's own scenes and assets (and
// small images of every format, written here) rather than committed as binaries, plus the
// inputs the fuzzers found (tests/fuzz/regressions):
//   lucent_fuzz_seeds SOURCE_DIR OUT_DIR
// writes OUT_DIR/{scene,obj,texture,render_image,part}/.
#include <stb/stb_image_write.h>
#include <tinyexr.h>
#include <zlib.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz_common.hpp"
#include "image/image_probe.hpp"
#include "lucent/compare.hpp"
#include "lucent/image.hpp"
#include "lucent/parts.hpp"

namespace fs = std::filesystem;
using Parts = std::vector<std::pair<std::string, std::string>>;

namespace {

std::string read(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void put(const fs::path& dir, const std::string& name, const std::string& bytes) {
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary) << bytes;
}

std::string be32(std::uint32_t v) { return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }

// A 16-bit RGB PNG (stb_image_write writes only 8-bit).
std::string png16(int w, int h) {
  std::string raw;
  for (int y = 0; y < h; ++y) {
    raw += '\0';
    for (int i = 0; i < w * 3; ++i) {
      std::uint16_t v = static_cast<std::uint16_t>((y * 7919 + i * 104729) & 0xFFFF);
      raw += char(v >> 8);
      raw += char(v & 0xFF);
    }
  }
  uLongf zlen = compressBound(raw.size());
  std::string z(zlen, '\0');
  compress2(reinterpret_cast<Bytef*>(&z[0]), &zlen, reinterpret_cast<const Bytef*>(raw.data()),
            raw.size(), 9);
  z.resize(zlen);
  auto chunk = [](const std::string& tag, const std::string& data) {
    std::string td = tag + data;
    return be32(static_cast<std::uint32_t>(data.size())) + td +
           be32(static_cast<std::uint32_t>(
               crc32(0, reinterpret_cast<const Bytef*>(td.data()), td.size())));
  };
  std::string ihdr = be32(w) + be32(h) + std::string("\x10\x02\x00\x00\x00", 5);
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", z) +
         chunk("IEND", "");
}

void append(void* ctx, void* data, int size) {
  static_cast<std::string*>(ctx)->append(static_cast<const char*>(data), size);
}

// Small images of every format and variant lucent reads; name -> bytes.
Parts images() {
  Parts out;
  const int w = 9, h = 5;
  std::vector<unsigned char> rgba(w * h * 4);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = static_cast<unsigned char>((i * 37) % 256);
  std::vector<float> hdr(w * h * 3);
  for (size_t i = 0; i < hdr.size(); ++i) hdr[i] = 0.1f * float(i % 13);
  for (int comp : {1, 2, 3, 4}) {
    const std::string n = std::to_string(comp);
    std::string png, bmp, tga, jpg;
    stbi_write_png_to_func(append, &png, w, h, comp, rgba.data(), w * comp);
    stbi_write_bmp_to_func(append, &bmp, w, h, comp, rgba.data());
    stbi_write_tga_with_rle = comp % 2;
    stbi_write_tga_to_func(append, &tga, w, h, comp, rgba.data());
    stbi_write_jpg_to_func(append, &jpg, w, h, comp, rgba.data(), 80);
    out.emplace_back("c" + n + ".png", png);
    out.emplace_back("c" + n + ".bmp", bmp);
    out.emplace_back("c" + n + ".tga", tga);
    out.emplace_back("c" + n + ".jpg", jpg);
  }
  for (int width : {3, 9}) {  // flat and run-length encoded scanlines
    std::string bytes;
    stbi_write_hdr_to_func(append, &bytes, width, 3, 3, hdr.data());
    out.emplace_back("w" + std::to_string(width) + ".hdr", bytes);
  }
  out.emplace_back("rgb16.png", png16(4, 3));
  lucent::Image img{w, h, std::vector<float>(hdr.begin(), hdr.end())};
  std::string tmp = (fs::temp_directory_path() / "lucent-seed").string();
  for (const char* ext : {".pfm", ".exr"}) {
    lucent::write_image(tmp + ext, img);
    out.emplace_back(std::string("img") + ext, read(tmp + ext));
    fs::remove(tmp + ext);
  }
  out.emplace_back("grey.pfm", "Pf\n2 2\n-1.0\n" + std::string(16, '\0'));
  lucent::RenderResult r;
  r.mean = img;
  r.variance = img;
  r.samples.assign(static_cast<size_t>(w) * h, 16);
  lucent::write_render_exr(tmp + ".exr", r);
  out.emplace_back("render.exr", read(tmp + ".exr"));
  fs::remove(tmp + ".exr");
  int compressions[] = {TINYEXR_COMPRESSIONTYPE_NONE, TINYEXR_COMPRESSIONTYPE_RLE,
                        TINYEXR_COMPRESSIONTYPE_ZIPS, TINYEXR_COMPRESSIONTYPE_ZIP,
                        TINYEXR_COMPRESSIONTYPE_PIZ};
  // scanline files: half in every compression (0.25 to 0.5 in steps of 1/16), float (0 to 1.5)
  using lucent::fuzz::ExrLayout;
  for (int c : compressions) {
    ExrLayout half;
    half.compression = c;
    half.pixel_type = TINYEXR_PIXELTYPE_HALF;
    auto value = [](int ch, int x, int y) {
      return 0.25f + 0.0625f * float(((y * 5 + x) * (ch + 1)) % 5);
    };
    out.emplace_back("half" + std::to_string(c) + ".exr",
                     lucent::fuzz::exr_file(5, 40, {"B", "G", "R"}, value, half));
  }
  auto quarters = [](int w) {
    return [w](int ch, int x, int y) { return 0.25f * float(((y * w + x) * (ch + 3)) % 7); };
  };
  ExrLayout uncompressed;
  uncompressed.compression = TINYEXR_COMPRESSIONTYPE_NONE;
  out.emplace_back("y.exr", lucent::fuzz::exr_file(4, 4, {"Y"}, quarters(4), uncompressed));
  out.emplace_back("rgba.exr", lucent::fuzz::exr_file(4, 4, {"A", "B", "G", "R"}, quarters(4)));
  // tiled: 11 x 6 in tiles of 4, cut at the right and bottom edges
  out.emplace_back(
      "tiled.exr",
      lucent::fuzz::exr_file(11, 6, {"B", "G", "R"},
                             [](int c, int x, int y) { return 0.5f * float(x + y + c); }, {4}));
  return out;
}

// Images whose palette has fewer entries than their indices can name (image_decode.cpp,
// pad_palette): PNGs of colour type 3 at each bit depth with a short PLTE, and BMPs of 1, 4 and
// 8 bits with a short colour table (a Windows header's 4-byte entries, an OS/2 header's 3-byte).
Parts short_palettes() {
  Parts out;
  auto chunk = [](const std::string& tag, const std::string& data) {
    const std::string td = tag + data;
    return be32(static_cast<std::uint32_t>(data.size())) + td +
           be32(static_cast<std::uint32_t>(
               crc32(0, reinterpret_cast<const Bytef*>(td.data()), td.size())));
  };
  const int w = 5, h = 3;
  for (int depth : {1, 2, 4, 8}) {
    const int entries = depth == 1 ? 1 : 3;  // of 2, 4, 16, 256
    const int stride = (w * depth + 7) / 8;
    std::string raw;
    for (int y = 0; y < h; ++y) {
      raw += '\0';
      for (int i = 0; i < stride; ++i)  // indices past the palette's entries too
        raw += char((y * 37 + i * 91) & 0xff);
    }
    uLongf zlen = compressBound(raw.size());
    std::string z(zlen, '\0');
    compress2(reinterpret_cast<Bytef*>(&z[0]), &zlen, reinterpret_cast<const Bytef*>(raw.data()),
              raw.size(), 9);
    z.resize(zlen);
    std::string plte;
    for (int e = 0; e < entries; ++e) plte += {char(40 * e), char(200 - 30 * e), char(7 * e)};
    const std::string ihdr = be32(w) + be32(h) + std::string{char(depth), 3, 0, 0, 0};
    out.emplace_back("palette" + std::to_string(depth) + ".png",
                     std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) +
                         chunk("PLTE", plte) + chunk("IDAT", z) + chunk("IEND", ""));
  }
  auto le = [](std::uint32_t v, int n) {
    std::string s;
    for (int i = 0; i < n; ++i) s += char(v >> (8 * i));
    return s;
  };
  for (int bpp : {1, 4, 8})
    for (bool os2 : {false, true}) {
      const int entries = bpp == 1 ? 1 : 3, entry = os2 ? 3 : 4, hsz = os2 ? 12 : 40;
      const int stride = (w * bpp + 31) / 32 * 4;
      const std::uint32_t offset = 14 + hsz + entries * entry;
      std::string f = "BM" + le(offset + stride * h, 4) + le(0, 4) + le(offset, 4) + le(hsz, 4);
      if (os2)
        f += le(w, 2) + le(h, 2) + le(1, 2) + le(bpp, 2);
      else
        f += le(w, 4) + le(h, 4) + le(1, 2) + le(bpp, 2) + le(0, 4) + le(stride * h, 4) +
             le(2835, 4) + le(2835, 4) + le(entries, 4) + le(0, 4);
      for (int e = 0; e < entries; ++e)
        f += std::string{char(9 * e), char(120 + 40 * e), char(250 - 60 * e)} +
             std::string(entry - 3, '\0');
      for (int i = 0; i < stride * h; ++i) f += char((i * 53 + 11) & 0xff);
      out.emplace_back("palette" + std::to_string(bpp) + (os2 ? "-os2" : "") + ".bmp", f);
    }
  return out;
}

// `exr` (an OpenEXR's bytes) stored uncompressed, its channels and attributes as they were: part
// seeds whose sums and counts the fuzzer reaches byte for byte (the writer compresses).
std::string uncompressed_exr(const std::string& exr) {
  const auto* d = reinterpret_cast<const unsigned char*>(exr.data());
  EXRVersion version;
  EXRHeader header;
  EXRImage image;
  InitEXRHeader(&header);
  InitEXRImage(&image);
  const char* err = nullptr;
  if (ParseEXRVersionFromMemory(&version, d, exr.size()) != TINYEXR_SUCCESS ||
      ParseEXRHeaderFromMemory(&header, &version, d, exr.size(), &err) != TINYEXR_SUCCESS ||
      LoadEXRImageFromMemory(&image, &header, d, exr.size(), &err) != TINYEXR_SUCCESS) {
    if (err) FreeEXRErrorMessage(err);
    std::fprintf(stderr, "lucent_fuzz_seeds: cannot read back a part seed\n");
    std::exit(1);
  }
  header.compression_type = TINYEXR_COMPRESSIONTYPE_NONE;
  for (int c = 0; c < header.num_channels; ++c)
    header.requested_pixel_types[c] = header.pixel_types[c];
  std::string out = lucent::image_detail::save_exr_to_memory("uncompressed_exr", image, header);
  FreeEXRImage(&image);
  FreeEXRHeader(&header);
  return out;
}

// Part files and checkpoints of 2x2 to 8x8 pixels made by write_render_part (ZIP, PIZ, and the
// same uncompressed), and renders with lucent's attributes (a caustics render's light variance,
// a seed and sampler, with and without the variance layers): what the part readers and
// read_render take.
Parts part_files() {
  Parts out;
  const std::string tmp = (fs::temp_directory_path() / "lucent-part-seed.exr").string();
  auto part = [](int w, int h, std::vector<lucent::SampleRange> samples,
                 std::vector<lucent::SampleRange> requested, std::uint64_t nonfinite) {
    lucent::RenderPart p;
    lucent::PartInfo& info = p.info;
    info.width = w;
    info.height = h;
    info.scene_hash = 0x0123456789abcdefull;
    info.seed = 7;
    info.sampler = "sobol";
    info.integrator = "path";
    info.version = "0.1.0";
    info.scene = "scene.json";
    info.samples = std::move(samples);
    info.requested = std::move(requested);
    info.rays = 12345;
    info.seconds = 0.25;
    std::uint64_t spp = 0;
    for (const auto& r : info.samples) spp += r.end - r.begin;
    lucent::Accumulation& a = p.acc;
    a.width = w;
    a.height = h;
    const size_t n = size_t(w) * h;
    a.count.assign(n, static_cast<std::uint32_t>(spp));
    for (std::uint64_t k = 0; k < nonfinite; ++k) a.count[k % n] -= 1;  // (nonfinite <= n)
    info.nonfinite = nonfinite;
    for (size_t i = 0; i < n * 3; ++i) {
      const double v = 0.125 * double((i * 7) % 11), c = a.count[i / 3];
      a.sum.push_back(v * c);
      a.sumsq.push_back(v * v * c + 0.5 * (i % 2));
    }
    return p;
  };
  auto put_part = [&](const std::string& name, const lucent::RenderPart& p,
                      lucent::PartCompression c) {
    lucent::write_render_part(tmp, p, c);
    out.emplace_back(name + ".exr", read(tmp));
    out.emplace_back(name + "-raw.exr", uncompressed_exr(read(tmp)));
    fs::remove(tmp);
  };
  using lucent::PartCompression;
  put_part("part2x2", part(2, 2, {{0, 4}}, {{0, 4}}, 0), PartCompression::zip);
  // a checkpoint (PIZ): [0, 3) of [0, 8), one non-finite sample
  put_part("checkpoint3x2", part(3, 2, {{0, 3}}, {{0, 8}}, 1), PartCompression::piz);
  // a merge of two ranges, of a part file without a sampler (before 24 Nov 2026), a display
  lucent::RenderPart merged = part(8, 8, {{0, 4}, {8, 12}}, {{0, 16}}, 3);
  merged.info.sampler.clear();
  merged.info.display = {lucent::Transfer::Gamma, 1.8, -0.5, lucent::ToneMap::Aces};
  put_part("merged8x8", merged, PartCompression::zip);
  // renders: a caustics render's light variance with its statistics, the mean alone
  lucent::RenderResult r;
  r.mean = lucent::Image{4, 3, std::vector<float>(36, 0.5f)};
  r.variance = lucent::Image{4, 3, std::vector<float>(36, 0.0625f)};
  r.samples.assign(12, 16);
  r.seed = 3;
  r.sampler = "independent";
  r.light_mean_variance = lucent::LightMeanVariance{{1e-3, 2e-3, 0}, {4e-4, 0, 5e-5}};
  lucent::write_render_exr(tmp, r);
  out.emplace_back("caustics4x3.exr", read(tmp));
  r.variance = {};
  r.samples.clear();
  r.light_mean_variance.reset();
  lucent::write_render_exr(tmp, r);
  out.emplace_back("seeded-mean4x3.exr", read(tmp));
  fs::remove(tmp);
  return out;
}

const char* const kObjs[] = {
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
    "f 1/1/1 2/2/1 3/3/1 4/1/1\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nl 1 2\np 3\n",
    "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 1 0\nv 0 2 0\nf 1 2 3 4 5\n",
    "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n"
    "usemtl b\nf 1//1 3//1 2//1\nvn 0 0 1\n",
};
const char kMtl[] =
    "newmtl a\nKd 0.5 0.5 0.5\nKs 0.1 0.1 0.1\nNs 20\nillum 2\nmap_Kd c3.png\n"
    "newmtl b\nKd 0 0 0\nKs 1 1 1\nillum 3\nKe 1 2 3\nNi 1.4\nd 0.5\n";

std::string find(const Parts& parts, const std::string& name) {
  for (const auto& [n, b] : parts)
    if (n == name) return b;
  return "";
}

// An OBJ and the files it names, as a bundle: mtllib and map_* renamed to local parts.
std::string obj_bundle(const fs::path& obj) {
  std::string text = read(obj);
  Parts parts;
  std::smatch m;
  static const std::regex mtllib(R"(mtllib\s+(\S+))"), map(R"((map_\w+|bump|disp)\s+(\S+))");
  std::string rewritten;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (std::regex_search(line, m, mtllib)) {
      std::string mtl = read(obj.parent_path() / m[1].str());
      std::string mtl_out;
      std::istringstream min(mtl);
      for (std::string l; std::getline(min, l);) {
        std::smatch mm;
        if (std::regex_search(l, mm, map)) {
          fs::path tex = obj.parent_path() / mm[2].str();
          if (fs::exists(tex) && fs::file_size(tex) < 8192) {
            parts.emplace_back("t" + std::to_string(parts.size()) + tex.extension().string(),
                               read(tex));
            l = mm[1].str() + " " + parts.back().first;
          }
        }
        mtl_out += l + "\n";
      }
      parts.emplace_back("m.mtl", mtl_out);
      line = "mtllib m.mtl";
    }
    rewritten += line + "\n";
  }
  return lucent::fuzz::make_bundle(rewritten, parts);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s SOURCE_DIR OUT_DIR\n", argv[0]);
    return 2;
  }
  const fs::path src = argv[1], out = argv[2];
  const Parts imgs = images();
  for (const auto& [name, bytes] : imgs) {
    put(out / "texture", name, bytes);
    put(out / "render_image", name, bytes);
  }
  for (const auto& [name, bytes] : short_palettes()) {
    put(out / "texture", name, bytes);
    put(out / "render_image", name, bytes);
  }
  for (const auto& [name, bytes] : part_files()) {
    put(out / "part", name, bytes);
    put(out / "render_image", name, bytes);
  }
  for (const auto& e : fs::recursive_directory_iterator(src / "assets")) {
    if (!e.is_regular_file()) continue;
    const std::string ext = e.path().extension().string();
    if ((ext == ".png" || ext == ".jpg") && e.file_size() < 65536) {
      put(out / "texture", e.path().filename().string(), read(e.path()));
    } else if (ext == ".obj") {
      put(out / "obj", e.path().filename().string(), obj_bundle(e.path()));
    }
  }
  int k = 0;
  for (const char* o : kObjs)
    put(out / "obj", "small" + std::to_string(k++) + ".obj",
        lucent::fuzz::make_bundle(o, {{"m.mtl", kMtl}, {"c3.png", find(imgs, "c3.png")}}));

  // scenes: each project scene as it is, and with its files made parts of the bundle
  for (const auto& e : fs::directory_iterator(src / "scenes")) {
    if (e.path().extension() != ".json") continue;
    const std::string text = read(e.path());
    put(out / "scene", e.path().filename().string(), text);
    nlohmann::json j = nlohmann::json::parse(text);
    Parts parts;
    int n = 0;
    if (!j.contains("shapes")) j["shapes"] = nlohmann::json::array();
    if (!j.contains("materials")) j["materials"] = nlohmann::json::object();
    for (auto& shape : j["shapes"]) {
      if (!shape.contains("file")) continue;
      fs::path obj = e.path().parent_path() / shape["file"].get<std::string>();
      if (!fs::exists(obj) || fs::file_size(obj) > 8192) continue;
      std::string name = "o" + std::to_string(n++) + ".obj";
      lucent::fuzz::Bundle b;
      std::string bundle = obj_bundle(obj);
      const auto* d = reinterpret_cast<const std::uint8_t*>(bundle.data());
      b = lucent::fuzz::parse_bundle(d, bundle.size());
      parts.emplace_back(name, b.main);
      for (auto& p : b.parts) parts.push_back(p);
      shape["file"] = name;
    }
    for (auto& m : j["materials"]) {
      if (m.contains("albedo") && m["albedo"].is_object()) {
        m["albedo"]["texture"] = "c4.png";
        parts.emplace_back("c4.png", find(imgs, "c4.png"));
      }
    }
    j["film"]["width"] = 8;
    j["film"]["height"] = 8;
    put(out / "scene", "local-" + e.path().filename().string(),
        lucent::fuzz::make_bundle(j.dump(1), parts));
  }
  // the inputs the fuzzers found (crashes, leaks, over-reads): every run replays them
  const fs::path found = src / "tests/fuzz/regressions";
  for (const char* target : {"scene", "obj", "texture", "render_image", "part"})
    if (fs::is_directory(found / target))
      for (const auto& e : fs::directory_iterator(found / target))
        put(out / target, "regression-" + e.path().filename().string(), read(e.path()));

  const char* env_scene =
      R"({"film": {"width": 4, "height": 4}, "lights": [{"type": "environment", "file": "%s", "scale": 2}]})";
  for (const char* f : {"w9.hdr", "img.pfm", "img.exr", "c3.png"}) {
    char buf[256];
    std::snprintf(buf, sizeof buf, env_scene, f);
    put(out / "scene", std::string("env-") + f + ".json",
        lucent::fuzz::make_bundle(buf, {{f, find(imgs, f)}}));
  }
  return 0;
}
