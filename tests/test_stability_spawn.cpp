// Self-intersection of spawned rays (issue 5 item 5.6): hit points made on spheres and triangles
// the way the renderer makes them (interaction_from_hit), rays spawned from them with
// lc_spawn_origin into both hemispheres, traced against the same primitive with the real
// intersection code (kernels/test/stability_spawn.cl). For every magnitude decade 1e-8 ... 1e8
// of the coordinates: 10^6 spawned rays, and the test asserts zero self-hits (and zero rays that
// enter a sphere and miss its far side). Not a statistical test: any failure is a bug.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <glm/glm.hpp>
#include <random>
#include <sstream>
#include <vector>

#include "cl/context.hpp"
#include "cl/kernel_source.hpp"
#include "cl/program_cache.hpp"
#include "probe_launch.hpp"
#include "render/pack.hpp"
#include "shared/types.h"
#include "support.hpp"

namespace test_stability_spawn {

namespace {

struct SpawnProbe {
  explicit SpawnProbe(const std::string& options)
      : program(lucent::cl_util::build_program_cached(
            ctx,
            lucent::detail::assemble_kernel_source("test/stability_spawn.cl",
                                                   lucent::test::kernel_dir()),
            options, lucent::test::cache_dir())) {}
  lucent::cl_util::Context ctx{lucent::test::device()};
  cl::Program program;
};

// The probe in float, or in double (-D LC_DOUBLE, --precision double: tests/test_precision.cpp).
SpawnProbe& probe(bool in_double = false) {
  static SpawnProbe p("-cl-std=CL1.2");
  if (!in_double) return p;
  static SpawnProbe d("-cl-std=CL1.2 -D LC_DOUBLE");
  return d;
}

struct Counts {
  int hits = 0, rays = 0, self_hits = 0, far_misses = 0, generation_misses = 0;
  int per_case[16] = {};  ///< [8 k + 4 is_triangle + case], k = 0 self-hits, 1 far misses
  cl_float4 example[2];
};

// Spheres and triangles whose coordinates have magnitude m: centres at distance 0.5 m to 2 m from
// the origin in random directions, sizes (radius, edge) log-uniform from 1e-4 m to m.
Counts run_decade(double m, int rays_wanted, std::uint32_t seed, bool in_double = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  auto unit = [&]() {
    double z = 1 - 2 * u(rng), phi = 2 * M_PI * u(rng), s = std::sqrt(1 - z * z);
    return glm::dvec3(s * std::cos(phi), s * std::sin(phi), z);
  };
  auto put = [](float* dst, glm::dvec3 v) {
    for (int k = 0; k < 3; ++k) dst[k] = static_cast<float>(v[k]);
  };
  const int kPrims = 256;
  std::vector<lc_sphere> spheres;
  std::vector<lc_triangle> triangles;
  for (int i = 0; i < kPrims; ++i) {
    lc_sphere s{};
    put(s.center, m * (0.5 + 1.5 * u(rng)) * unit());
    s.radius = static_cast<float>(m * std::pow(10.0, -4 * u(rng)));
    s.light = LC_INVALID;
    spheres.push_back(s);
  }
  while (static_cast<int>(triangles.size()) < kPrims) {
    glm::dvec3 g = m * (0.5 + 1.5 * u(rng)) * unit();
    double size = m * std::pow(10.0, -4 * u(rng));
    glm::dvec3 v[3] = {g + size * unit(), g + size * unit(), g + size * unit()};
    if (glm::length(glm::cross(v[1] - v[0], v[2] - v[0])) < 0.05 * size * size) continue;
    lc_triangle t{};
    put(t.v0, v[0]);
    put(t.v1, v[1]);
    put(t.v2, v[2]);
    t.light = LC_INVALID;
    if (!lucent::render_detail::set_triangle_normal(t)) continue;  // collinear in float
    triangles.push_back(t);
  }
  SpawnProbe& p = probe(in_double);
  cl::Buffer bs(p.ctx.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                spheres.size() * sizeof(lc_sphere), spheres.data());
  cl::Buffer bt(p.ctx.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                triangles.size() * sizeof(lc_triangle), triangles.data());
  cl_int zero[21] = {};
  cl::Buffer bc(p.ctx.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, sizeof zero, zero);
  cl::Buffer be(p.ctx.context, CL_MEM_READ_WRITE, 2 * sizeof(cl_float4));
  cl::Kernel k(p.program, "stability_spawn");
  lucent::test::set_args(k, 0, bs, static_cast<cl_uint>(spheres.size()), bt,
                         static_cast<cl_uint>(triangles.size()), static_cast<cl_uint>(seed), bc,
                         be);
  // two rays per hit point; a few aimed rays miss (grazing a triangle's edge) and are skipped
  const std::size_t items = static_cast<std::size_t>(rays_wanted / 2 * 1.02);
  lucent::test::launch_probe(p.ctx.queue, k, items);
  cl_int out[21];
  Counts c;
  p.ctx.queue.enqueueReadBuffer(bc, CL_TRUE, 0, sizeof out, out);
  p.ctx.queue.enqueueReadBuffer(be, CL_TRUE, 0, sizeof c.example, c.example);
  c.hits = out[0];
  c.rays = out[1];
  c.self_hits = out[2];
  c.far_misses = out[3];
  c.generation_misses = out[4];
  for (int i = 0; i < 16; ++i) c.per_case[i] = out[5 + i];
  return c;
}

void expect_no_self_intersection(int e, int rays, bool in_double) {
  Counts c =
      run_decade(std::pow(10.0, e), rays, 1234u + static_cast<std::uint32_t>(e + 8), in_double);
  EXPECT_GE(c.rays, rays) << "hit points " << c.hits << ", aimed rays that missed "
                          << c.generation_misses;
  const char* kinds[] = {"outside hit, reflection side", "outside hit, transmission side",
                         "inside hit, reflection side", "inside hit, transmission side"};
  auto where = [&]() {
    std::ostringstream s;
    for (int k = 0; k < 16; ++k)
      if (c.per_case[k])
        s << (k < 8 ? "self-hits" : "missed far sides") << ", " << (k & 4 ? "triangle" : "sphere")
          << " " << kinds[k & 3] << ": " << c.per_case[k] << "\n";
    s << "last failure: p = (" << c.example[0].s[0] << ", " << c.example[0].s[1] << ", "
      << c.example[0].s[2] << "), "
      << (static_cast<int>(c.example[0].s[3]) & 4 ? "triangle " : "sphere ")
      << kinds[static_cast<int>(c.example[0].s[3]) & 3] << ", d = (" << c.example[1].s[0] << ", "
      << c.example[1].s[1] << ", " << c.example[1].s[2] << "), t = " << c.example[1].s[3];
    return s.str();
  };
  EXPECT_EQ(c.self_hits, 0) << "of " << c.rays << " rays at magnitude 1e" << e << "; " << where();
  EXPECT_EQ(c.far_misses, 0) << "of " << c.rays << " rays at magnitude 1e" << e << "; " << where();
}

// lc_step_along, lc_spawn_origin's one-ulp step (integer steps of the bits), is
// nextafter(o, copysign(inf, n)) per component where n is not zero, and o where it is: checked
// against std::nextafter on the host for zeros of either sign (o = +-0 with n of either sign),
// subnormals, the largest values, powers of two (where an ulp changes size), values between
// floats (in double) and random values, in float and in double.
template <typename Real>
void expect_spawn_step_is_nextafter(bool in_double) {
  std::vector<Real> values;  // finite in Real (the step is nextafter for finite o)
  for (double v : {0.0,    -0.0,    1e-45,   -1e-45, 1e-39,
                   -3e-39, 1.0,     -1.0,    2.0,    -0.5,
                   3.4e38, -3.4e38, 1e-30,   7.5,    -1e8,
                   0.1,    1e-320,  -5e-324, 1e300,  1.0 + std::ldexp(1.0, -40)})
    if (std::isfinite(Real(v))) values.push_back(Real(v));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> ex(-40, 38);
  for (int k = 0; k < 48; ++k) values.push_back(Real(std::ldexp(u(rng), ex(rng))));
  const Real signs[] = {1, -1, 0, -Real(0), 0.25, -3};
  std::vector<Real> in;  // (o, 0) then (n, 0) per work-item
  for (size_t a = 0; a < values.size(); ++a)
    for (size_t s = 0; s < 6; ++s) {
      Real o[3] = {values[a], -values[a], values[(a + 3) % values.size()]};
      Real n[3] = {signs[s], signs[(s + 1) % 6], signs[(s + a) % 6]};
      in.insert(in.end(), {o[0], o[1], o[2], 0, n[0], n[1], n[2], 0});
    }
  const size_t count = in.size() / 8;
  SpawnProbe& pr = probe(in_double);
  cl::Buffer bi(pr.ctx.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, in.size() * sizeof(Real),
                in.data());
  cl::Buffer bo(pr.ctx.context, CL_MEM_WRITE_ONLY, count * 4 * sizeof(Real));
  cl::Kernel k(pr.program, "probe_spawn_step");
  lucent::test::set_args(k, 0, bi, bo);
  lucent::test::launch_probe(pr.ctx.queue, k, count);
  std::vector<Real> out = lucent::test::read_back<Real>(pr.ctx.queue, bo, count * 4);
  int checked_zero = 0;
  for (size_t i = 0; i < count; ++i)
    for (int c = 0; c < 3; ++c) {
      Real o = in[8 * i + c], n = in[8 * i + 4 + c], got = out[4 * i + c];
      Real want = n == 0 ? o : std::nextafter(o, std::copysign(Real(INFINITY), n));
      checked_zero += o == 0 && n != 0;
      ASSERT_TRUE(std::memcmp(&got, &want, sizeof(Real)) == 0)
          << "o = " << o << ", n = " << n << ": got " << got << ", nextafter gives " << want;
    }
  EXPECT_GT(checked_zero, 8);  // the zero cases were reached
}

TEST(SpawnStep, IsNextafterInFloat) { expect_spawn_step_is_nextafter<float>(false); }

TEST(SpawnStep, IsNextafterInDouble) {
  lucent::cl_util::Context ctx{lucent::test::device()};
  if (!ctx.device.info.fp64) GTEST_SKIP() << "the OpenCL device has no fp64";
  expect_spawn_step_is_nextafter<double>(true);
}

class StabilitySpawn : public ::testing::TestWithParam<int> {};

TEST_P(StabilitySpawn, NoSelfIntersection) {
  expect_no_self_intersection(GetParam(), 1000000, false);
}

INSTANTIATE_TEST_SUITE_P(Magnitudes, StabilitySpawn, ::testing::Range(-8, 9),
                         [](const ::testing::TestParamInfo<int>& i) {
                           return (i.param < 0 ? "1em" : "1e") + std::to_string(std::abs(i.param));
                         });

// The same in double (--precision double): offsets ~5e8 times smaller (double's error bounds),
// still no self-hit and no missed far side, over a wider range than float's: 1e-30 to 1e16.
// (Float, run at these magnitudes once: ~2500 triangle self-hits in 8.6e5 rays at 1e-12, where
// products of coordinates fall below float's normal range; 25% sphere self-hits at 1e-20 and
// 1e-30; at 1e16 39% of the aimed rays miss.) 2 x 10^5 rays per magnitude.
class StabilitySpawnDouble : public ::testing::TestWithParam<int> {};

TEST_P(StabilitySpawnDouble, NoSelfIntersection) {
  lucent::cl_util::Context ctx{lucent::test::device()};
  if (!ctx.device.info.fp64) GTEST_SKIP() << "the OpenCL device has no fp64";
  expect_no_self_intersection(GetParam(), 200000, true);
}

INSTANTIATE_TEST_SUITE_P(Magnitudes, StabilitySpawnDouble,
                         ::testing::Values(-30, -20, -12, -8, -4, 0, 4, 8, 12, 16),
                         [](const ::testing::TestParamInfo<int>& i) {
                           return (i.param < 0 ? "1em" : "1e") + std::to_string(std::abs(i.param));
                         });

}  // namespace

}  // namespace test_stability_spawn
