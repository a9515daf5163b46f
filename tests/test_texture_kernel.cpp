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
  cl::Program program = lucent::cl_util::build_program(
      ctx,
      lucent::detail::assemble_kernel_source("test/texture_probe.cl", lucent::test::kernel_dir()),
      "-cl-std=CL1.2");
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

std::vector<cl_float4> lookup(const lucent::Scene& scene, const std::vector<Query>& q) {
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
  cl::Kernel k(p.program, "probe_texture_lookup");
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

}  // namespace test_texture_kernel
