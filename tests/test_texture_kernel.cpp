// The kernel's texture lookup (kernels/film/texture.cl) through a probe kernel, on several textures
// packed by render_detail::pack_scene into one texel buffer with per-texture offsets. Expected
// values come from the rendering model (docs/rendering-model.md): uv (0,0) is the bottom-left
// corner of the image, bilinear filtering between texel centres, repeat wrapping.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cl/context.hpp"
#include "cl/kernel_source.hpp"
#include "probe_launch.hpp"
#include "reference/texture.hpp"
#include "render/pack.hpp"
#include "support.hpp"

namespace test_texture_kernel {

namespace {

struct Probe {
  lucent::cl_util::Context ctx{lucent::test::device()};
  std::string source =
      lucent::detail::assemble_kernel_source("test/texture_probe.cl", lucent::test::kernel_dir());
  cl::Program program = lucent::cl_util::build_program(ctx, source, "-cl-std=CL1.2");
  /// with the texture mapping (wrap modes, uv scale and offset) compiled in
  cl::Program mapped_program;
  cl::Program& mapped() {
    if (mapped_program() == nullptr)
      mapped_program =
          lucent::cl_util::build_program(ctx, source, "-cl-std=CL1.2 -D LC_HAS_TEXTURE_MAPPING");
    return mapped_program;
  }
};

Probe& probe() {
  static Probe p;
  return p;
}

// Texture `id` of size w x h whose texel (x, y) (y = 0 the top row) holds (x, y, id, 1 + x*y)
// plus a per-texture offset, so that every texel of every texture is distinct.
lucent::Texture make_texture(int id, int w, int h) {
  lucent::Texture t;
  t.path = "probe" + std::to_string(id);
  t.width = w;
  t.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      t.rgba.insert(t.rgba.end(), {float(x), float(y), float(10 * id), float(1 + x * y)});
  return t;
}

struct Query {
  int texture;
  float u, v;
};

std::vector<cl_float4> lookup(const lucent::Scene& scene, const std::vector<Query>& q,
                              bool mapping = false) {
  lucent::render_detail::PackedScene packed = lucent::render_detail::pack_scene(scene);
  Probe& p = probe();
  std::vector<cl_int> index;
  std::vector<cl_float2> uv;
  for (const Query& e : q) {
    index.push_back(e.texture);
    uv.push_back({{e.u, e.v}});
  }
  auto& c = p.ctx.context;
  cl::Buffer b_tex(c, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                   packed.textures.size() * sizeof(lc_texture), packed.textures.data());
  cl::Buffer b_texels(c, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                      packed.texels.size() * sizeof(cl_float4), packed.texels.data());
  cl::Buffer b_index(c, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, index.size() * sizeof(cl_int),
                     index.data());
  cl::Buffer b_uv(c, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, uv.size() * sizeof(cl_float2),
                  uv.data());
  cl::Buffer b_out(c, CL_MEM_WRITE_ONLY, q.size() * sizeof(cl_float4));
  cl::Kernel k(mapping ? p.mapped() : p.program, "probe_texture_lookup");
  lucent::test::set_args(k, 0, b_tex, b_texels, b_index, b_uv, b_out);
  lucent::test::launch_probe(p.ctx.queue, k, q.size());
  std::vector<cl_float4> out = lucent::test::read_back<cl_float4>(p.ctx.queue, b_out, q.size());
  return out;
}

lucent::Scene three_textures() {
  lucent::Scene s;
  s.textures.push_back(make_texture(0, 4, 2));
  s.textures.push_back(make_texture(1, 3, 5));
  s.textures.push_back(make_texture(2, 1, 1));
  return s;
}

// The texel (x, y) of texture t as the host stored it, x and y wrapped.
std::vector<float> host_texel(const lucent::Texture& t, int x, int y) {
  x = ((x % t.width) + t.width) % t.width;
  y = ((y % t.height) + t.height) % t.height;
  const float* p = &t.rgba[(static_cast<size_t>(y) * t.width + x) * 4];
  return {p[0], p[1], p[2], p[3]};
}

void expect_value(const cl_float4& got, const std::vector<float>& want, const std::string& what) {
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(got.s[c], want[c], 1e-4) << what << " channel " << c;
}

TEST(TextureKernel, TexelCentresGiveTheirTexelsInEveryPackedTexture) {
  lucent::Scene s = three_textures();
  std::vector<Query> q;
  std::vector<std::vector<float>> want;
  std::vector<std::string> what;
  for (int id = 0; id < 3; ++id) {
    const lucent::Texture& t = s.textures[id];
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x) {
        // centre of texel (x, y): u grows to the right, v grows upwards from the bottom row
        q.push_back({id, (x + 0.5f) / t.width, 1.0f - (y + 0.5f) / t.height});
        want.push_back(host_texel(t, x, y));
        what.push_back("texture " + std::to_string(id) + " texel (" + std::to_string(x) + ", " +
                       std::to_string(y) + ")");
      }
  }
  std::vector<cl_float4> got = lookup(s, q);
  for (size_t i = 0; i < q.size(); ++i) expect_value(got[i], want[i], what[i]);
}

TEST(TextureKernel, UvOriginIsTheBottomLeftCorner) {
  lucent::Scene s = three_textures();
  const lucent::Texture& t = s.textures[1];  // 3 x 5
  // just inside each corner the lookup is the corner texel
  float e = 0.25f / 5;  // a quarter texel from the edges
  std::vector<cl_float4> got = lookup(s, {{1, e / 3 * 5, e}, {1, 1 - e / 3 * 5, 1 - e}});
  // (u, v) = (0, 0) region: bilinear between the corner texel and its wrapped neighbours; at a
  // quarter texel from the edge the corner texel weighs 3/4 in each direction
  auto mix = [&](int x0, int y0, int x1, int y1) {
    std::vector<float> r(4);
    for (int c = 0; c < 4; ++c)
      r[c] = 0.75f * 0.75f * host_texel(t, x0, y0)[c] + 0.25f * 0.75f * host_texel(t, x1, y0)[c] +
             0.75f * 0.25f * host_texel(t, x0, y1)[c] + 0.25f * 0.25f * host_texel(t, x1, y1)[c];
    return r;
  };
  expect_value(got[0], mix(0, 4, -1, 5), "bottom-left corner (bottom row is y = 4)");
  expect_value(got[1], mix(2, 0, 3, -1), "top-right corner (top row is y = 0)");
}

TEST(TextureKernel, BilinearMixBetweenTexelCentres) {
  lucent::Scene s = three_textures();
  const lucent::Texture& t = s.textures[0];  // 4 x 2
  std::vector<Query> q;
  std::vector<std::vector<float>> want;
  // between texels (1,0), (2,0), (1,1), (2,1): fractions fx along x, fy along y (downwards)
  for (float fx : {0.0f, 0.25f, 0.5f, 0.9f})
    for (float fy : {0.0f, 0.3f, 0.5f, 1.0f}) {
      float x = 1.5f + fx, y = 0.5f + fy;  // film position in texels, y from the top
      q.push_back({0, x / t.width, 1.0f - y / t.height});
      std::vector<float> r(4);
      for (int c = 0; c < 4; ++c)
        r[c] = (1 - fx) * (1 - fy) * host_texel(t, 1, 0)[c] +
               fx * (1 - fy) * host_texel(t, 2, 0)[c] + (1 - fx) * fy * host_texel(t, 1, 1)[c] +
               fx * fy * host_texel(t, 2, 1)[c];
      want.push_back(r);
    }
  std::vector<cl_float4> got = lookup(s, q);
  for (size_t i = 0; i < q.size(); ++i)
    expect_value(got[i], want[i],
                 "uv (" + std::to_string(q[i].u) + ", " + std::to_string(q[i].v) + ")");
}

TEST(TextureKernel, RepeatWrapping) {
  lucent::Scene s = three_textures();
  const lucent::Texture& t = s.textures[1];  // 3 x 5
  std::vector<Query> q;
  std::vector<std::vector<float>> want;
  // uv and uv shifted by whole periods (both signs) give the same value
  const float base[][2] = {{0.1f, 0.2f}, {0.5f, 0.5f}, {0.8f, 0.95f}, {0.3f, 0.7f}};
  const float shift[][2] = {{1, 0}, {-1, 0}, {0, 2}, {-3, -1}, {5, 7}};
  for (auto& b : base) {
    q.push_back({1, b[0], b[1]});
    for (auto& d : shift) q.push_back({1, b[0] + d[0], b[1] + d[1]});
  }
  std::vector<cl_float4> got = lookup(s, q);
  size_t per = 1 + sizeof(shift) / sizeof(shift[0]);
  for (size_t i = 0; i < q.size(); ++i) {
    const cl_float4& ref = got[i / per * per];
    for (int c = 0; c < 4; ++c)
      EXPECT_NEAR(got[i].s[c], ref.s[c], 1e-3) << "uv (" << q[i].u << ", " << q[i].v << ")";
  }
  // at the left edge (u = 0) x falls half-way between the last and the first column
  std::vector<cl_float4> edge = lookup(s, {{1, 0.0f, 1.0f - 2.5f / 5}, {1, 0.5f, 0.0f}});
  std::vector<float> lr(4), tb(4);
  for (int c = 0; c < 4; ++c) {
    lr[c] = 0.5f * host_texel(t, 2, 2)[c] + 0.5f * host_texel(t, 0, 2)[c];
    tb[c] = 0.5f * host_texel(t, 1, 4)[c] + 0.5f * host_texel(t, 1, 0)[c];
  }
  expect_value(edge[0], lr, "u = 0: mix of the last and the first column");
  expect_value(edge[1], tb, "v = 0: mix of the bottom and the top row");
}

TEST(TextureKernel, OneTexelTextureIsConstant) {
  lucent::Scene s = three_textures();
  std::vector<cl_float4> got = lookup(s, {{2, 0.0f, 0.0f}, {2, 0.37f, 0.91f}, {2, -4.2f, 17.5f}});
  for (const cl_float4& g : got) expect_value(g, host_texel(s.textures[2], 0, 0), "1x1 texture");
}

TEST(TextureKernel, NonFiniteUvStaysInsideTheTexture) {
  lucent::Scene s = three_textures();
  const float nan = std::nanf(""), inf = INFINITY;
  std::vector<cl_float4> got =
      lookup(s, {{1, nan, 0.5f}, {1, 0.5f, nan}, {1, inf, -inf}, {0, nan, nan}});
  for (size_t i = 0; i < got.size(); ++i) {
    const lucent::Texture& t = s.textures[i < 3 ? 1 : 0];
    // every value is a convex mix of the texture's texels: within their range
    for (int c = 0; c < 4; ++c) {
      float lo = 1e30f, hi = -1e30f;
      for (size_t k = c; k < t.rgba.size(); k += 4) {
        lo = std::min(lo, t.rgba[k]);
        hi = std::max(hi, t.rgba[k]);
      }
      EXPECT_TRUE(std::isfinite(got[i].s[c])) << "query " << i;
      EXPECT_GE(got[i].s[c], lo - 1e-4f) << "query " << i;
      EXPECT_LE(got[i].s[c], hi + 1e-4f) << "query " << i;
    }
  }
}

}  // namespace

// The reference samples textures as the kernel does (src/reference/texture.cpp), non-finite uvs
// included: they read uv 0 in that coordinate. The reference returned NaN for them (a NaN
// converted to an integer texel index, and NaN weights), so that a scene the kernel rendered was
// black in the reference.
TEST(TextureKernel, ReferenceLookupMatchesTheKernelAtNonFiniteUvs) {
  lucent::Scene s = three_textures();
  const float nan = std::nanf(""), inf = INFINITY;
  const std::vector<Query> q = {{1, nan, 0.3f}, {1, 0.7f, nan},  {1, inf, -inf},
                                {0, nan, nan},  {0, 0.0f, 0.3f}, {1, 0.7f, 0.0f}};
  std::vector<cl_float4> got = lookup(s, q);
  for (size_t i = 0; i < q.size(); ++i) {
    const glm::dvec3 ref = lucent::ref::texture_rgb(s.textures[q[i].texture], {q[i].u, q[i].v});
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(std::isfinite(ref[c])) << "query " << i;
      EXPECT_NEAR(ref[c], got[i].s[c], 1e-4) << "query " << i << " channel " << c;
    }
  }
  // uv (NaN, 0.3) reads (0, 0.3), as a finite u of 0 does
  const glm::dvec3 at_nan = lucent::ref::texture_rgb(s.textures[1], {nan, 0.3});
  const glm::dvec3 at_zero = lucent::ref::texture_rgb(s.textures[1], {0.0, 0.3});
  for (int c = 0; c < 3; ++c) EXPECT_EQ(at_nan[c], at_zero[c]);
}

namespace {

// ---------------------------------------------------------------------------------------------
// Texture mapping (docs/rendering-model.md, "Textures"): a material reads its texture at
// uv * scale + offset, wrapped in u and v by repeat, clamp (to edge) or mirror. The cases below
// name the texel a lookup must give by hand: a lookup at a texel's centre gives that texel, and
// the wrap modes put texel centres outside [0, 1] where the closed forms say (clamp: the edge
// texel; mirror: period 2, [1, 2] the image backwards; repeat: period 1).

using lucent::TextureWrap;
constexpr TextureWrap kRepeat = TextureWrap::Repeat, kClamp = TextureWrap::Clamp,
                      kMirror = TextureWrap::Mirror;

struct Mapping {
  TextureWrap wu, wv;
  double su, sv, ou, ov;
};

// the centre of column x and row y (from the top) of texture 1 (3 x 5) in texture space
double cu(int x) { return (x + 0.5) / 3; }
double cv(int y) { return 1 - (y + 0.5) / 5; }

struct MappedCase {
  Mapping m;
  double tu, tv;  ///< where the lookup lands in texture space (uv * scale + offset)
  int x, y;       ///< the texel it must give (-1: the half-and-half mix of columns 2 and 0)
};

const MappedCase kMappedCases[] = {
    // clamp: every coordinate beyond an edge reads the edge texel
    {{kClamp, kClamp, 1, 1, 0, 0}, cu(1), 7.0, 1, 0},
    {{kClamp, kClamp, 1, 1, 0, 0}, -2.3, cv(3), 0, 3},
    {{kClamp, kClamp, 1, 1, 0, 0}, 5.1, -0.4, 2, 4},
    {{kClamp, kClamp, 1, 1, 0, 0}, 1e5, -1e5, 2, 4},
    {{kClamp, kClamp, 1, 1, 0, 0}, 0.0, 1.0, 0, 0},  // the corner: no mix with the far edge
    // mirror: [1, 2] is [0, 1] backwards, period 2 both ways
    {{kMirror, kMirror, 1, 1, 0, 0}, 2 - cu(0), cv(1), 0, 1},
    {{kMirror, kMirror, 1, 1, 0, 0}, -cu(2), 2 + cv(4), 2, 4},
    {{kMirror, kMirror, 1, 1, 0, 0}, 4 - cu(1), -cv(3), 1, 3},
    {{kMirror, kMirror, 1, 1, 0, 0}, -3 + cu(0), cv(2), 2, 2},
    {{kMirror, kMirror, 1, 1, 0, 0}, 0.0, 0.0, 0, 4},  // an edge reads its own texel both sides
    {{kMirror, kMirror, 1, 1, 0, 0}, 1.0, 1.0, 2, 0},
    // each axis its own mode: u repeats, v clamps
    {{kRepeat, kClamp, 1, 1, 0, 0}, cu(1) + 5, 9.0, 1, 0},
    {{kRepeat, kClamp, 1, 1, 0, 0}, cu(2) - 3, -9.0, 2, 4},
    {{kRepeat, kClamp, 1, 1, 0, 0}, 0.0, cv(2), -1, 2},  // u = 0 still mixes the far column
    // scales (negative: the image mirrored) and offsets (large: reduced by whole periods)
    {{kRepeat, kRepeat, 2, -3, 0.25, 0.5}, cu(0) + 1, cv(2) - 2, 0, 2},
    {{kRepeat, kRepeat, 2, -3, 0.25, 0.5}, cu(2) - 4, cv(4) + 7, 2, 4},
    {{kClamp, kClamp, 0.5, 4, -0.25, 0.1}, cu(2), cv(1), 2, 1},
    {{kClamp, kClamp, 0.5, 4, -0.25, 0.1}, -1.0, 3.0, 0, 0},
    {{kMirror, kMirror, -1.5, 0.75, 3.5, -7.25}, 2 - cu(1), cv(0) + 2, 1, 0},
    {{kMirror, kMirror, -1.5, 0.75, 3.5, -7.25}, -cu(0), -cv(3), 0, 3},
    {{kRepeat, kRepeat, 1, 1, 1000.25, -999.5}, cu(1) + 1000, cv(3) - 999, 1, 3},
};

lucent::Material mapped_material(const Mapping& m, int texture) {
  lucent::Material mat;
  mat.name = "mapped";
  mat.albedo_texture = texture;
  mat.albedo_wrap_u = m.wu;
  mat.albedo_wrap_v = m.wv;
  mat.albedo_uv_scale = {m.su, m.sv};
  mat.albedo_uv_offset = {m.ou, m.ov};
  return mat;
}

// The uv at which a case's lookup lands where it says.
glm::dvec2 case_uv(const MappedCase& c) {
  return {(c.tu - c.m.ou) / c.m.su, (c.tv - c.m.ov) / c.m.sv};
}

std::vector<float> case_value(const lucent::Texture& t, const MappedCase& c) {
  if (c.x >= 0) return host_texel(t, c.x, c.y);
  std::vector<float> r(4);
  for (int k = 0; k < 4; ++k) r[k] = 0.5f * (host_texel(t, 2, c.y)[k] + host_texel(t, 0, c.y)[k]);
  return r;
}

std::string case_name(const MappedCase& c) {
  return std::string("wrap ") + lucent::texture_wrap_name(c.m.wu) + "/" +
         lucent::texture_wrap_name(c.m.wv) + " scale (" + std::to_string(c.m.su) + ", " +
         std::to_string(c.m.sv) + ") offset (" + std::to_string(c.m.ou) + ", " +
         std::to_string(c.m.ov) + ") at texture-space (" + std::to_string(c.tu) + ", " +
         std::to_string(c.tv) + ")";
}

// three_textures() and a material per case mapping texture 1; the device texture each material's
// lookups read (pack_scene's header for its mapping) in `index`.
lucent::Scene mapped_scene(std::vector<int>& index) {
  lucent::Scene s = three_textures();
  for (const MappedCase& c : kMappedCases) s.materials.push_back(mapped_material(c.m, 1));
  lucent::render_detail::PackedScene packed = lucent::render_detail::pack_scene(s);
  index.clear();
  for (const lc_material& m : packed.materials) index.push_back(m.p.diffuse.albedo_tex);
  return s;
}

TEST(TextureKernel, WrapModesScalesAndOffsetsGiveTheClosedFormsTexels) {
  std::vector<int> index;
  lucent::Scene s = mapped_scene(index);
  std::vector<Query> q;
  for (std::size_t i = 0; i < std::size(kMappedCases); ++i) {
    const glm::dvec2 uv = case_uv(kMappedCases[i]);
    q.push_back({index[i], float(uv.x), float(uv.y)});
  }
  std::vector<cl_float4> got = lookup(s, q, true);
  for (std::size_t i = 0; i < q.size(); ++i)
    expect_value(got[i], case_value(s.textures[1], kMappedCases[i]), case_name(kMappedCases[i]));
}

TEST(TextureKernel, ReferenceWrapModesScalesAndOffsetsGiveTheClosedFormsTexels) {
  const lucent::Texture t = three_textures().textures[1];
  for (const MappedCase& c : kMappedCases) {
    const glm::dvec3 got =
        lucent::ref::texture_rgb(t, case_uv(c), c.m.wu, c.m.wv, {c.m.su, c.m.sv}, {c.m.ou, c.m.ov});
    const std::vector<float> want = case_value(t, c);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 1e-9) << case_name(c);
  }
}

// Between texel centres too: the kernel (texel indices wrapped) and the reference (coordinates
// folded into [0, 1], then clamped) agree on a grid of uvs over [-2.2, 2.2]^2 for every case's
// mapping. Every mode's lookup is continuous in uv, so float and double differ by rounding only.
TEST(TextureKernel, MappedLookupsMatchTheReferenceBetweenTexelCentres) {
  std::vector<int> index;
  lucent::Scene s = mapped_scene(index);
  std::vector<Query> q;
  std::vector<std::size_t> which;
  for (std::size_t i = 0; i < std::size(kMappedCases); ++i)
    for (double u = -2.2; u <= 2.2; u += 0.37)
      for (double v = -2.2; v <= 2.2; v += 0.29) {
        q.push_back({index[i], float(u), float(v)});
        which.push_back(i);
      }
  std::vector<cl_float4> got = lookup(s, q, true);
  for (std::size_t i = 0; i < q.size(); ++i) {
    const Mapping& m = kMappedCases[which[i]].m;
    const glm::dvec3 ref = lucent::ref::texture_rgb(s.textures[1], {q[i].u, q[i].v}, m.wu, m.wv,
                                                    {m.su, m.sv}, {m.ou, m.ov});
    for (int k = 0; k < 3; ++k)
      ASSERT_NEAR(got[i].s[k], ref[k], 2e-3)
          << case_name(kMappedCases[which[i]]) << " uv (" << q[i].u << ", " << q[i].v << ")";
  }
}

// The default mapping is today's lookup to the bit: a kernel built with the mapping code reads a
// texture mapped by default (its header's scale 1, offset 0, repeat) as the kernel without it.
TEST(TextureKernel, DefaultMappingIsTheRepeatLookupToTheBit) {
  lucent::Scene s = three_textures();
  std::vector<Query> q;
  for (int id = 0; id < 3; ++id)
    for (float u = -3.1f; u < 3.2f; u += 0.173f)
      for (float v = -2.9f; v < 3.0f; v += 0.231f) q.push_back({id, u, v});
  std::vector<cl_float4> plain = lookup(s, q, false), mapped = lookup(s, q, true);
  for (std::size_t i = 0; i < q.size(); ++i)
    for (int c = 0; c < 4; ++c)
      ASSERT_EQ(plain[i].s[c], mapped[i].s[c]) << "uv (" << q[i].u << ", " << q[i].v << ")";
}

// An image is held once however its materials map it: a header per (texture, mapping), on the
// same texels; the scene's textures keep their indices (mapped by default: environment maps and
// default materials read them).
TEST(TextureKernel, MappedTexturesShareTheirTexels) {
  lucent::Scene s = three_textures();
  const Mapping clamp{kClamp, kClamp, 1, 1, 0, 0}, scaled{kRepeat, kMirror, 2, 2, 0.5, 0};
  s.materials = {mapped_material(clamp, 1), mapped_material(scaled, 1), mapped_material(clamp, 1),
                 mapped_material({kRepeat, kRepeat, 1, 1, 0, 0}, 1), mapped_material(clamp, 0)};
  const lucent::render_detail::PackedScene p = lucent::render_detail::pack_scene(s);
  ASSERT_EQ(p.texels.size(), 4u * 2 + 3 * 5 + 1);
  ASSERT_EQ(p.textures.size(), 3u + 3);  // the scene's three, then clamp-1, scaled-1, clamp-0
  std::vector<int> tex;
  for (const lc_material& m : p.materials) tex.push_back(m.p.diffuse.albedo_tex);
  EXPECT_EQ(tex, (std::vector<int>{3, 4, 3, 1, 5}));
  for (int i : {1, 3, 4}) EXPECT_EQ(p.textures[i].offset, p.textures[1].offset) << i;
  EXPECT_EQ(p.textures[5].offset, p.textures[0].offset);
  EXPECT_EQ(p.textures[3].wrap, LC_WRAP_CLAMP | (LC_WRAP_CLAMP << LC_WRAP_V_SHIFT));
  EXPECT_EQ(p.textures[4].wrap, LC_WRAP_REPEAT | (LC_WRAP_MIRROR << LC_WRAP_V_SHIFT));
  EXPECT_EQ(p.textures[4].uv_scale[0], 2.0f);
  EXPECT_EQ(p.textures[4].uv_offset[0], 0.5f);
  for (int i : {0, 1, 2}) {
    EXPECT_EQ(p.textures[i].wrap, 0u) << i;
    EXPECT_EQ(p.textures[i].uv_scale[0], 1.0f) << i;
    EXPECT_EQ(p.textures[i].uv_scale[1], 1.0f) << i;
    EXPECT_EQ(p.textures[i].uv_offset[0], 0.0f) << i;
  }
}

}  // namespace

}  // namespace test_texture_kernel
