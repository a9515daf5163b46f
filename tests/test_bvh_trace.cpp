// Kernel traversal (kernels/bvh/traverse.cl, geom/triangle.cl, geom/sphere.cl) against a brute
// force reference computed here, in double, over every primitive.
//
// Reference: a triangle is hit where the three signed volumes [d, vi - o, vj - o] share a sign
// (barycentrics b = volume / sum, margin = min b); a sphere where the discriminant of
// |o + t d - c|^2 = r^2 is positive (margin = discriminant / (r^2 |d|^2)). A primitive is "surely"
// hit when its margin exceeds kMargin and "possibly" hit when it exceeds -kMargin: float and
// double may disagree only within kMargin of an edge or a silhouette.
//
// Per ray the kernel's answer passes when: on a miss, no primitive is surely hit in (0, tmax); on
// a hit, its primitive is possibly hit at a distance within kTol (relative) of the kernel's t and
// no surely-hit primitive is closer than that t by more than kTol. Any-hit (shadow) rays pass when
// "occluded" comes with some primitive possibly hit before tmax, and "free" with none surely hit.
// Barycentrics of triangle hits agree within 1e-4. Exact agreement (same primitive as the closest
// surely-hit one) is also required for all but 0.1% of the rays, so the tolerances cannot hide a
// systematic error.
//
// Closed meshes: rays aimed exactly at shared vertices and edges (from inside, or from outside
// through a convex mesh) must hit, a triangle that owns the vertex or edge, at the expected
// distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bvh/bvh.hpp"
#include "cl/context.hpp"
#include "support.hpp"
#include "support/device_tracer.hpp"
#include "support/test_meshes.hpp"

namespace test_bvh_trace {

namespace {

using lucent::bvh::Bvh;
using lucent::bvh::TraceHit;
using lucent::bvh::TraceRay;

constexpr double kMargin = 1e-5;  // barycentric / relative-discriminant ambiguity band
constexpr double kTol = 1e-5;     // relative t tolerance: |t_kernel - t_ref| <= kTol * (t_ref + 1)

struct D3 {
  double x, y, z;
};
D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator*(double s, D3 a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 cross(D3 a, D3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
D3 d3(const float* p) { return {p[0], p[1], p[2]}; }

struct Scene {
  std::vector<lc_triangle> tris;
  std::vector<lc_sphere> spheres;
};

struct RefHit {
  double t = INFINITY, margin = -INFINITY, b1 = 0, b2 = 0;
};

// Reference intersection of a ray with one primitive, or margin = -inf when the ray's line misses
// it by far or runs parallel to it.
RefHit ref_prim(const Scene& s, lc_uint ref, D3 o, D3 d) {
  RefHit h;
  if (ref & LC_PRIM_SPHERE_BIT) {
    const lc_sphere& sp = s.spheres[ref & ~LC_PRIM_SPHERE_BIT];
    D3 f = o - d3(sp.center);
    double r = sp.radius, a = dot(d, d), b = dot(f, d);
    D3 l = f - (b / a) * d;  // centre to its closest point on the line
    double disc = r * r - dot(l, l);
    h.margin = r > 0 ? disc / (r * r) : -INFINITY;
    if (disc < 0 && h.margin < -kMargin) return h;
    double sq = std::sqrt(std::max(0.0, disc * a)), c = dot(f, f) - r * r;
    double q = -b - std::copysign(sq, b);
    double t0 = c / q, t1 = q / a;
    if (t0 > t1) std::swap(t0, t1);
    h.t = t0 > 0 ? t0 : (t1 > 0 ? t1 : INFINITY);
    return h;
  }
  const lc_triangle& t = s.tris[ref];
  D3 a = d3(t.v0) - o, b = d3(t.v1) - o, c = d3(t.v2) - o;
  double u = dot(d, cross(c, b)), v = dot(d, cross(a, c)), w = dot(d, cross(b, a));
  double det = u + v + w;
  if (det == 0) return h;
  h.margin = std::min({u / det, v / det, w / det});
  h.b1 = v / det;
  h.b2 = w / det;
  D3 n = cross(d3(t.v1) - d3(t.v0), d3(t.v2) - d3(t.v0));
  double dn = dot(n, d);
  if (dn == 0) return h;
  h.t = dot(n, a) / dn;
  // nearly parallel to the plane: the float test may land anywhere near the edges
  if (std::fabs(dn) < 1e-4 * std::sqrt(dot(n, n) * dot(d, d))) h.margin = std::min(h.margin, 0.0);
  return h;
}

struct Verdict {
  bool ok = true;
  bool exact = true;
  std::string why;
};

Verdict judge(const Scene& s, const TraceRay& r, const TraceHit& k, bool any_hit) {
  D3 o = d3(r.o), d = d3(r.d);
  double tmax = r.tmax;
  std::size_t n = s.tris.size() + s.spheres.size();
  double best_sure = INFINITY;
  lc_uint best_prim = LC_INVALID;
  RefHit at_kernel;
  bool kernel_possible = false, possible_block = false;
  for (std::size_t i = 0; i < n; ++i) {
    lc_uint ref = i < s.tris.size() ? lc_uint(i) : lc_uint(i - s.tris.size()) | LC_PRIM_SPHERE_BIT;
    RefHit h = ref_prim(s, ref, o, d);
    if (!(h.t > 0)) continue;
    if (h.margin > kMargin && h.t < tmax && h.t < best_sure) {
      best_sure = h.t;
      best_prim = ref;
    }
    if (h.margin > -kMargin && h.t < tmax * (1 + kTol) + kTol) possible_block = true;
    if (ref == k.prim && h.margin > -kMargin) {
      at_kernel = h;
      kernel_possible = true;
    }
  }
  Verdict v;
  double tol = kTol * (best_sure == INFINITY ? 1.0 : best_sure + 1.0);
  if (any_hit) {
    bool occluded = k.prim != LC_INVALID;
    bool sure_block = best_sure < tmax * (1 - kTol) - kTol;
    v.exact = occluded == (best_prim != LC_INVALID);
    if (!occluded && sure_block) v.ok = false, v.why = "not occluded, reference finds a blocker";
    if (occluded && !possible_block) v.ok = false, v.why = "occluded, reference finds no blocker";
    return v;
  }
  v.exact = k.prim == best_prim;
  if (k.prim == LC_INVALID) {
    if (best_prim != LC_INVALID) v.ok = false, v.why = "kernel misses, reference hits";
    return v;
  }
  if (!kernel_possible) {
    v.ok = false;
    v.why = "kernel hits a primitive the reference does not";
    return v;
  }
  double tk = k.t;
  if (std::fabs(tk - at_kernel.t) > kTol * (at_kernel.t + 1)) {
    v.ok = false;
    v.why =
        "t differs: kernel " + std::to_string(tk) + ", reference " + std::to_string(at_kernel.t);
  } else if (best_sure < tk - tol) {
    v.ok = false;
    v.why = "a closer primitive is surely hit";
  } else if (!(k.prim & LC_PRIM_SPHERE_BIT) && at_kernel.margin > kMargin &&
             (std::fabs(k.b1 - at_kernel.b1) > 1e-4 || std::fabs(k.b2 - at_kernel.b2) > 1e-4)) {
    v.ok = false;
    v.why = "barycentrics differ";
  }
  return v;
}

class BvhTrace : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ctx_ = std::make_unique<lucent::cl_util::Context>(lucent::test::device());
  }
  static void TearDownTestSuite() { ctx_.reset(); }

  std::vector<TraceHit> trace(const Scene& s, const Bvh& b, const std::vector<TraceRay>& rays,
                              bool any_hit = false) {
    lucent::bvh::DeviceTracer tracer(*ctx_, s.tris, s.spheres, b, "", lucent::test::cache_dir());
    return tracer.trace(rays, any_hit);
  }

  // Traces `rays` and judges every one against the brute force; returns the number checked.
  void compare(const Scene& s, const std::vector<TraceRay>& rays, bool any_hit = false,
               const char* what = "", const lucent::bvh::BuildOptions& options = {}) {
    Bvh b = lucent::bvh::build(s.tris, s.spheres, options);
    auto hits = trace(s, b, rays, any_hit);
    std::size_t bad = 0, inexact = 0, hit = 0;
    // the kernel's answers do not depend on the host's sanitizers: under them (where the brute
    // force runs instrumented) every fourth ray is judged
    const std::size_t step = lucent::test::kAddressSanitizer ? 4 : 1;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      hit += hits[i].prim != LC_INVALID;
      if (i % step) continue;
      Verdict v = judge(s, rays[i], hits[i], any_hit);
      inexact += !v.exact;
      if (!v.ok && ++bad <= 5) {
        const TraceRay& r = rays[i];
        ADD_FAILURE() << what << " ray " << i << " o=(" << r.o[0] << "," << r.o[1] << "," << r.o[2]
                      << ") d=(" << r.d[0] << "," << r.d[1] << "," << r.d[2] << ") tmax=" << r.tmax
                      << ": " << v.why << " (kernel prim " << hits[i].prim << ", t " << hits[i].t
                      << ")";
      }
    }
    EXPECT_EQ(bad, 0u) << what;
    EXPECT_LE(inexact, rays.size() / 1000) << what << ": too many rays differ within tolerance";
    // the ray sets are built to hit often and miss often: a tracer that always misses fails here
    EXPECT_GT(hit, rays.size() / 10) << what;
    EXPECT_LT(hit, rays.size()) << what;
  }

  static std::unique_ptr<lucent::cl_util::Context> ctx_;
};
std::unique_ptr<lucent::cl_util::Context> BvhTrace::ctx_;

TraceRay make_ray(D3 o, D3 d, float tmax = INFINITY) {
  double l = std::sqrt(dot(d, d));
  TraceRay r{};
  r.o[0] = float(o.x), r.o[1] = float(o.y), r.o[2] = float(o.z);
  r.d[0] = float(d.x / l), r.d[1] = float(d.y / l), r.d[2] = float(d.z / l);
  r.tmax = tmax;
  return r;
}

D3 random_dir(std::mt19937& rng) {
  std::normal_distribution<double> g;
  D3 d{g(rng), g(rng), g(rng)};
  return (1 / std::sqrt(dot(d, d))) * d;
}

// Random rays from a box around the unit cube; tmax infinite or, with finite, random in (0, 1).
std::vector<TraceRay> random_rays(int n, unsigned seed, bool finite = false, double lo = -0.3,
                                  double hi = 1.3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi), t(0.05, 1.0);
  std::vector<TraceRay> rays;
  for (int i = 0; i < n; ++i)
    rays.push_back(
        make_ray({u(rng), u(rng), u(rng)}, random_dir(rng), finite ? float(t(rng)) : INFINITY));
  return rays;
}

Scene soup(int n, unsigned seed, float size) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1), s(-size, size);
  Scene sc;
  for (int i = 0; i < n; ++i) {
    float c[3] = {u(rng), u(rng), u(rng)};
    lc_triangle t{};
    for (int a = 0; a < 3; ++a) {
      t.v0[a] = c[a] + s(rng);
      t.v1[a] = c[a] + s(rng);
      t.v2[a] = c[a] + s(rng);
    }
    t.light = LC_INVALID;
    sc.tris.push_back(t);
  }
  return sc;
}

void add_spheres(Scene& sc, int n, unsigned seed, float rmin, float rmax, float offset = 0,
                 float spread = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, spread), r(rmin, rmax);
  for (int i = 0; i < n; ++i) {
    lc_sphere s{};
    for (int a = 0; a < 3; ++a) s.center[a] = offset + u(rng);
    s.radius = r(rng);
    s.light = LC_INVALID;
    sc.spheres.push_back(s);
  }
}

TEST_F(BvhTrace, RandomTriangleSoup) {
  Scene s = soup(1000, 11, 0.06f);
  compare(s, random_rays(20000, 12), false, "soup");
}

TEST_F(BvhTrace, SphereSets) {
  Scene s;
  add_spheres(s, 300, 13, 0.01f, 0.08f);
  compare(s, random_rays(15000, 14), false, "spheres");
  // small spheres far from the origin, rays starting near them (Ray Tracing Gems ch. 7)
  Scene far;
  add_spheres(far, 200, 15, 0.5f, 2.0f, 1.0e5f, 50.0f);
  std::mt19937 rng(16);
  std::uniform_real_distribution<double> u(1.0e5 - 10, 1.0e5 + 60);
  std::vector<TraceRay> rays;
  for (int i = 0; i < 10000; ++i)
    rays.push_back(make_ray({u(rng), u(rng), u(rng)}, random_dir(rng)));
  compare(far, rays, false, "far spheres");
}

TEST_F(BvhTrace, MixedTrianglesAndSpheres) {
  Scene s = soup(500, 17, 0.08f);
  add_spheres(s, 200, 18, 0.01f, 0.06f);
  compare(s, random_rays(20000, 19), false, "mix");
  // shadow rays: any-hit with finite tmax
  compare(s, random_rays(20000, 20, true), true, "mix any-hit");
  compare(s, random_rays(5000, 20, true), false, "mix finite tmax");
}

// On PoCL's x86-64 CPU device the traversal reduces its masks with movmskps and popcnt and takes a
// leaf block's nearest lane by vpermilps (kernels/bvh/traverse.cl, LC_BVH_MOVMSK; the renderer's
// device defines turn it on); without the device defines it compiles the portable forms that
// other devices run. Both must find the same hits, bit for bit: closest hits (t, primitive,
// barycentrics) and any-hit answers, on triangles and spheres together (the leaf's two mask
// tests) and on triangles alone.
TEST_F(BvhTrace, MaskIntrinsicsFindTheSameHitsAsThePortableForm) {
  Scene mix = soup(500, 41, 0.08f);
  add_spheres(mix, 200, 42, 0.01f, 0.06f);
  Scene tris = soup(1500, 43, 0.08f);
  for (const Scene* s : {&mix, &tris}) {
    SCOPED_TRACE(s == &mix ? "triangles and spheres" : "triangles");
    Bvh b = lucent::bvh::build(s->tris, s->spheres);
    lucent::bvh::DeviceTracer device(*ctx_, s->tris, s->spheres, b, "", lucent::test::cache_dir());
    lucent::bvh::DeviceTracer portable(*ctx_, s->tris, s->spheres, b, "", lucent::test::cache_dir(),
                                       "", false);
#if defined(__x86_64__)
    const bool expected =
        ctx_->device.info.type == "CPU" && lucent::cl_util::is_pocl(ctx_->device.info);
#else
    const bool expected = false;
#endif
    EXPECT_EQ(device.mask_intrinsics(), expected) << ctx_->device.info.name;
    EXPECT_FALSE(portable.mask_intrinsics());
    for (bool any_hit : {false, true}) {
      auto rays = random_rays(6000, 44 + any_hit, any_hit);
      auto a = device.trace(rays, any_hit), p = portable.trace(rays, any_hit);
      std::size_t differ = 0, hit = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        hit += a[i].prim != LC_INVALID;
        differ += std::memcmp(&a[i], &p[i], sizeof(TraceHit)) != 0;
      }
      EXPECT_EQ(differ, 0u) << (any_hit ? "any-hit" : "closest hit");
      EXPECT_GT(hit, rays.size() / 20) << "the rays must hit something to compare";
    }
  }
}

// Woop, Benthin and Wald's watertight test as the paper writes it, in float on the host: kx and
// ky swapped when d[kz] < 0, no fused multiply-add, and the kernel's recomputation in double of
// edge functions that round to 0. Returns t in (0, tmax), or INFINITY.
struct WoopHit {
  float t = INFINITY, b1 = 0, b2 = 0;
};
// x rounded to float where it stands: no product below is fused into an addition
float f32(float x) {
  volatile float v = x;
  return v;
}
// the axis of d's largest component, ties broken as geom/triangle.cl breaks them
int dominant_axis(const float* d) {
  float ad[3] = {std::fabs(d[0]), std::fabs(d[1]), std::fabs(d[2])};
  return ad[0] > ad[1] ? (ad[0] > ad[2] ? 0 : 2) : (ad[1] > ad[2] ? 1 : 2);
}
WoopHit woop_with_swap(const lc_triangle& tri, const TraceRay& r) {
  const float* d = r.d;
  int kz = dominant_axis(d);
  int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  if (d[kz] < 0) std::swap(kx, ky);
  float sx = d[kx] / d[kz], sy = d[ky] / d[kz], sz = 1.0f / d[kz];
  const float* v[3] = {tri.v0, tri.v1, tri.v2};
  float X[3], Y[3], Z[3];
  for (int j = 0; j < 3; ++j) {
    Z[j] = f32(v[j][kz] - r.o[kz]);
    X[j] = f32(f32(v[j][kx] - r.o[kx]) - f32(sx * Z[j]));
    Y[j] = f32(f32(v[j][ky] - r.o[ky]) - f32(sy * Z[j]));
  }
  float U = f32(f32(X[2] * Y[1]) - f32(Y[2] * X[1]));
  float V = f32(f32(X[0] * Y[2]) - f32(Y[0] * X[2]));
  float W = f32(f32(X[1] * Y[0]) - f32(Y[1] * X[0]));
  if (U == 0 || V == 0 || W == 0) {
    U = float(double(X[2]) * Y[1] - double(Y[2]) * X[1]);
    V = float(double(X[0]) * Y[2] - double(Y[0]) * X[2]);
    W = float(double(X[1]) * Y[0] - double(Y[1]) * X[0]);
  }
  WoopHit h;
  if ((U < 0 || V < 0 || W < 0) && (U > 0 || V > 0 || W > 0)) return h;
  float det = f32(f32(U + V) + W);
  if (det == 0) return h;
  float T = f32(f32(f32(U * f32(sz * Z[0])) + f32(V * f32(sz * Z[1]))) + f32(W * f32(sz * Z[2])));
  float inv = f32(1.0f / det);
  float t = f32(T * inv);
  if (!(t > 0 && t < r.tmax)) return h;
  h.t = t;
  h.b1 = f32(V * inv);
  h.b2 = f32(W * inv);
  return h;
}

// The kernel leaves out the paper's swap of kx and ky for d[kz] < 0 (geom/triangle.cl): its test
// is two-sided, and the swap only changes the signs of U, V, W, det and T, exactly. So its hits
// must be the paper's to the bit: t and barycentrics of the nearest triangle of a random soup,
// with the rays' dominant components of both signs.
TEST_F(BvhTrace, ShearWithoutSwapGivesTheWatertightTestsBits) {
  Scene s = soup(1000, 51, 0.08f);
  auto rays = random_rays(4000, 52);
  Bvh b = lucent::bvh::build(s.tris, s.spheres);
  auto hits = trace(s, b, rays);
  std::size_t compared = 0, negative = 0, differ = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    WoopHit best, second;
    lc_uint prim = LC_INVALID;
    for (std::size_t k = 0; k < s.tris.size(); ++k) {
      WoopHit h = woop_with_swap(s.tris[k], rays[i]);
      if (h.t < best.t) {
        second = best;
        best = h;
        prim = lc_uint(k);
      } else if (h.t < second.t) {
        second = h;
      }
    }
    if (prim == LC_INVALID || second.t == best.t) continue;  // a miss, or a tie the order decides
    ++compared;
    negative += rays[i].d[dominant_axis(rays[i].d)] < 0;
    const TraceHit& k = hits[i];
    if (k.prim != prim || std::memcmp(&k.t, &best.t, 4) || std::memcmp(&k.b1, &best.b1, 4) ||
        std::memcmp(&k.b2, &best.b2, 4)) {
      if (++differ <= 5)
        ADD_FAILURE() << "ray " << i << ": kernel prim " << k.prim << " t " << k.t << " b " << k.b1
                      << " " << k.b2 << ", paper's test prim " << prim << " t " << best.t << " b "
                      << best.b1 << " " << best.b2;
    }
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(compared, rays.size() / 5);
  EXPECT_GT(negative, compared / 3) << "rays whose dominant component is negative";
  EXPECT_GT(compared - negative, compared / 3) << "and positive";
}

// Rays along the axes (two direction components exactly 0: 1 / d is infinite).
TEST_F(BvhTrace, AxisParallelRays) {
  Scene s = soup(500, 21, 0.08f);
  add_spheres(s, 200, 22, 0.01f, 0.06f);
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  std::vector<TraceRay> rays;
  for (int i = 0; i < 12000; ++i) {
    D3 d{0, 0, 0};
    double sign = (i & 1) ? 1.0 : -1.0;
    if (i % 6 < 2)
      d.x = sign;
    else if (i % 6 < 4)
      d.y = sign;
    else
      d.z = sign;
    rays.push_back(make_ray({u(rng), u(rng), u(rng)}, d));
  }
  compare(s, rays, false, "axis-parallel");
}

// Rays whose origin lies exactly on a face of a BVH node's box, in any direction or moving
// within the face's plane.
TEST_F(BvhTrace, RaysStartingOnBoxFaces) {
  Scene s = soup(800, 24, 0.08f);
  add_spheres(s, 100, 25, 0.01f, 0.05f);
  Bvh b = lucent::bvh::build(s.tris, s.spheres);
  std::mt19937 rng(26);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<TraceRay> rays;
  for (int i = 0; i < 12000; ++i) {
    // a child box of a random node (the boxes the kernel tests)
    const lc_bvh_node& nd =
        b.nodes[std::uniform_int_distribution<std::size_t>(0, b.nodes.size() - 1)(rng)];
    int k = std::uniform_int_distribution<int>(0, LC_BVH_WIDTH - 1)(rng);
    if (nd.child[k] == LC_INVALID) k = 0;  // slot 0 is always used
    float lo[3], hi[3];
    for (int a = 0; a < 3; ++a) lo[a] = nd.bounds[2 * a][k], hi[a] = nd.bounds[2 * a + 1][k];
    int axis = i % 3;
    float o[3];
    for (int a = 0; a < 3; ++a) o[a] = float(lo[a] + u(rng) * (hi[a] - lo[a]));
    o[axis] = (i & 4) ? hi[axis] : lo[axis];
    D3 d = random_dir(rng);
    if (i & 8) {  // within the face plane
      if (axis == 0) d.x = 0;
      if (axis == 1) d.y = 0;
      if (axis == 2) d.z = 0;
    }
    rays.push_back(make_ray(d3(o), d, (i & 16) ? float(0.05 + u(rng)) : INFINITY));
  }
  compare(s, rays, false, "box faces");
  compare(s, rays, true, "box faces any-hit");
}

// Leaves of 1 to 16 primitives (1 to 4 leaf blocks), spheres and triangles sharing blocks, the
// classic per-primitive SAH cost too: closest hits, any-hit and axis-parallel rays. One test per
// leaf size: each judges 15,000 rays against the brute force over 1,600 primitives (it took 20 s
// under the sanitizers as one test).
class BvhTraceLeaves : public BvhTrace, public ::testing::WithParamInterface<int> {};

TEST_P(BvhTraceLeaves, LeafSizesAndMixedBlocks) {
  Scene s = soup(1200, 30, 0.07f);
  add_spheres(s, 400, 31, 0.01f, 0.05f);
  std::vector<TraceRay> axis;
  std::mt19937 rng(32);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  for (int i = 0; i < 3000; ++i) {
    D3 d{0, 0, 0};
    (&d.x)[i % 3] = (i & 4) ? 1.0 : -1.0;
    axis.push_back(make_ray({u(rng), u(rng), u(rng)}, d));
  }
  const int leaf = GetParam();
  lucent::bvh::BuildOptions o;
  o.max_leaf_size = leaf;
  o.leaf_block = leaf == 8 ? 1 : 4;
  std::string what = "leaves of " + std::to_string(leaf);
  compare(s, random_rays(6000, 33 + leaf), false, what.c_str(), o);
  compare(s, random_rays(6000, 34 + leaf, true), true, (what + " any-hit").c_str(), o);
  compare(s, axis, false, (what + " axis-parallel").c_str(), o);
}
INSTANTIATE_TEST_SUITE_P(MaxLeafSize, BvhTraceLeaves, ::testing::Values(1, 8, 16));

// No primitive: every ray misses. One primitive: the root's only child is a leaf.
TEST_F(BvhTrace, EmptySceneAndSinglePrimitive) {
  Scene empty;
  Bvh b = lucent::bvh::build(empty.tris, empty.spheres);
  auto rays = random_rays(1000, 40);
  for (bool any : {false, true}) {
    auto hits = trace(empty, b, rays, any);
    std::size_t hit = 0;
    for (auto& h : hits) hit += h.prim != LC_INVALID;
    EXPECT_EQ(hit, 0u);
  }
  Scene one;
  add_spheres(one, 1, 41, 0.45f, 0.5f, 0.45f, 0.1f);
  compare(one, random_rays(3000, 42), false, "one sphere");
  compare(one, random_rays(3000, 43, true), true, "one sphere any-hit");
}

// A ray with a NaN or infinite component (only a kernel bug could make one: scenes are checked)
// hits nothing, closest-hit and any-hit alike, instead of entering every child of every node,
// the empty slots too, and reading past the node array (a NaN camera crashed the renderer so).
TEST_F(BvhTrace, NonFiniteRaysHitNothing) {
  // 4 spheres: one wide node with empty slots (as the default scene's); 40: a deeper tree
  for (int n : {4, 40}) {
    Scene s;
    add_spheres(s, n, 44, 0.45f, 0.5f, 0.45f, 0.1f);
    Bvh b = lucent::bvh::build(s.tris, s.spheres);
    std::vector<TraceRay> rays = random_rays(64, 45);
    const float bad[] = {NAN, INFINITY, -INFINITY};
    for (std::size_t i = 0; i < rays.size(); ++i) {
      float* v = (i % 2) ? rays[i].o : rays[i].d;
      v[i / 2 % 3] = bad[i / 6 % 3];
      if (i % 8 == 0) {  // a NaN camera: every component, and no end
        for (int c = 0; c < 3; ++c) rays[i].o[c] = rays[i].d[c] = NAN;
        rays[i].tmax = INFINITY;
      }
    }
    for (bool any : {false, true})
      for (const TraceHit& h : trace(s, b, rays, any)) EXPECT_EQ(h.prim, LC_INVALID) << n;
    // and finite rays still hit
    std::size_t hits = 0;
    for (const TraceHit& h : trace(s, b, random_rays(64, 45), false)) hits += h.prim != LC_INVALID;
    EXPECT_GT(hits, 0u) << n;
  }
}

// --- closed meshes: no ray passes through -------------------------------------------------------

struct EdgeTarget {
  lc_uint a, b;  // vertex indices; a == b for a vertex
};

// True when face f of mesh m has vertex a and b.
bool owns(const lucent::bvh::meshes::IndexedMesh& m, lc_uint f, EdgeTarget e) {
  auto has = [&](lc_uint v) {
    return m.faces[f][0] == v || m.faces[f][1] == v || m.faces[f][2] == v;
  };
  return has(e.a) && has(e.b);
}

void expect_watertight(const lucent::bvh::meshes::IndexedMesh& m, const std::vector<TraceRay>& rays,
                       const std::vector<EdgeTarget>& targets, const std::vector<TraceHit>& hits,
                       bool check_owner, const char* what) {
  std::size_t missed = 0, wrong = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    D3 o = d3(rays[i].o);
    const EdgeTarget& e = targets[i];
    D3 p = 0.5 * (d3(m.positions[e.a].data()) + d3(m.positions[e.b].data()));
    double expect = std::sqrt(dot(p - o, p - o));
    if (hits[i].prim == LC_INVALID) {
      if (++missed <= 5)
        ADD_FAILURE() << what << ": ray " << i << " aimed at vertices " << e.a << "-" << e.b
                      << " passed through";
      continue;
    }
    bool ok = hits[i].t <= expect * (1 + kTol) + kTol;
    if (check_owner) ok = ok && owns(m, hits[i].prim, e) && hits[i].t >= expect * (1 - kTol) - kTol;
    if (!ok && ++wrong <= 5)
      ADD_FAILURE() << what << ": ray " << i << " aimed at vertices " << e.a << "-" << e.b
                    << " hit triangle " << hits[i].prim << " at t " << hits[i].t << ", expected "
                    << expect;
  }
  EXPECT_EQ(missed, 0u) << what;
  EXPECT_EQ(wrong, 0u) << what;
}

std::vector<EdgeTarget> vertices_and_edges(const lucent::bvh::meshes::IndexedMesh& m) {
  std::vector<EdgeTarget> t;
  for (lc_uint v = 0; v < m.positions.size(); ++v) t.push_back({v, v});
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k)
      if (f[k] < f[(k + 1) % 3]) t.push_back({f[k], f[(k + 1) % 3]});  // each edge once
  return t;
}

TEST_F(BvhTrace, IcosphereVerticesAndEdgesFromInsideAndOutside) {
  auto m = lucent::bvh::meshes::icosphere(4);  // 5120 faces, 2562 vertices, 7680 edges
  Scene s{m.triangles(), {}};
  Bvh b = lucent::bvh::build(s.tris, s.spheres);
  auto targets = vertices_and_edges(m);
  std::mt19937 rng(27);
  std::vector<TraceRay> inside, outside;
  for (const auto& e : targets) {
    D3 p = 0.5 * (d3(m.positions[e.a].data()) + d3(m.positions[e.b].data()));
    inside.push_back(make_ray({0, 0, 0}, p));
    // from outside, within 60 degrees of the outward normal (the sphere is convex)
    D3 n = (1 / std::sqrt(dot(p, p))) * p, w;
    do w = random_dir(rng);
    while (dot(w, n) < 0.5);
    D3 o = p + 2.0 * w;
    outside.push_back(make_ray(o, p - o));
  }
  expect_watertight(m, inside, targets, trace(s, b, inside), true, "icosphere from the centre");
  expect_watertight(m, outside, targets, trace(s, b, outside), true, "icosphere from outside");
  // random rays around it against the brute force (closest hit, t, barycentrics)
  compare(s, random_rays(4000, 29, false, -1.5, 1.5), false, "icosphere vs brute force");
}

TEST_F(BvhTrace, TorusVerticesAndEdgesFromInside) {
  const int nu = 96, nv = 48;
  const float R = 1.0f;
  auto m = lucent::bvh::meshes::torus(nu, nv, R, 0.3f);
  Scene s{m.triangles(), {}};
  Bvh b = lucent::bvh::build(s.tris, s.spheres);
  auto core = [&](double u) { return D3{R * std::cos(u), 0, R * std::sin(u)}; };
  auto id = [&](int i, int j) { return lc_uint((i % nu) * nv + (j % nv)); };
  // (1) in the plane of ring i, from its centre: the cut of the mesh there is the ring polygon,
  //     so the ray meets the aimed-at vertex or ring edge first
  std::vector<TraceRay> ring;
  std::vector<EdgeTarget> ring_t;
  // (2) across the strip between rings i and i + 1, from the core point halfway: must hit
  std::vector<TraceRay> cross;
  std::vector<EdgeTarget> cross_t;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      D3 o = core(2 * M_PI * i / nu), oh = core(2 * M_PI * (i + 0.5) / nu);
      for (EdgeTarget e : {EdgeTarget{id(i, j), id(i, j)}, EdgeTarget{id(i, j), id(i, j + 1)}}) {
        D3 p = 0.5 * (d3(m.positions[e.a].data()) + d3(m.positions[e.b].data()));
        ring.push_back(make_ray(o, p - o));
        ring_t.push_back(e);
      }
      for (EdgeTarget e :
           {EdgeTarget{id(i, j), id(i + 1, j)}, EdgeTarget{id(i, j), id(i + 1, j + 1)}}) {
        D3 p = 0.5 * (d3(m.positions[e.a].data()) + d3(m.positions[e.b].data()));
        cross.push_back(make_ray(oh, p - oh));
        cross_t.push_back(e);
      }
    }
  expect_watertight(m, ring, ring_t, trace(s, b, ring), true, "torus ring plane");
  expect_watertight(m, cross, cross_t, trace(s, b, cross), false, "torus across strips");
  // random directions from the core circle must all hit too
  std::mt19937 rng(28);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  std::vector<TraceRay> rnd;
  for (int i = 0; i < 20000; ++i) rnd.push_back(make_ray(core(u(rng)), random_dir(rng)));
  auto hits = trace(s, b, rnd);
  std::size_t missed = 0;
  for (auto& h : hits) missed += h.prim == LC_INVALID;
  EXPECT_EQ(missed, 0u) << "rays from inside the torus escaped";
}

// An axis-aligned cube made of 8x8 quads per face, vertices on exact binary fractions; the BVH's
// boxes share the cube's face planes. Rays run inside a face plane (direction component 0, origin
// on the box face) into the perpendicular face, through its edges and vertices: they must hit.
TEST_F(BvhTrace, AxisAlignedCubeRaysInFacePlanes) {
  lucent::bvh::meshes::IndexedMesh m;
  const int g = 8;
  auto vid = [&](float x, float y, float z) {
    for (lc_uint i = 0; i < m.positions.size(); ++i)
      if (m.positions[i][0] == x && m.positions[i][1] == y && m.positions[i][2] == z) return i;
    m.positions.push_back({x, y, z});
    return lc_uint(m.positions.size() - 1);
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < g; ++i)
        for (int j = 0; j < g; ++j) {
          lc_uint q[4];
          int corners[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
          for (int c = 0; c < 4; ++c) {
            float p[3];
            p[axis] = float(side);
            p[(axis + 1) % 3] = corners[c][0] / float(g);
            p[(axis + 2) % 3] = corners[c][1] / float(g);
            q[c] = vid(p[0], p[1], p[2]);
          }
          m.faces.push_back({q[0], q[1], q[2]});
          m.faces.push_back({q[0], q[2], q[3]});
        }
  Scene s{m.triangles(), {}};
  Bvh b = lucent::bvh::build(s.tris, s.spheres);
  std::vector<TraceRay> rays;
  std::vector<double> expect;
  for (int axis = 0; axis < 3; ++axis)                        // direction of travel
    for (int plane_axis = 0; plane_axis < 3; ++plane_axis) {  // the face plane the ray lies in
      if (plane_axis == axis) continue;
      int other = 3 - axis - plane_axis;
      for (int side = 0; side < 2; ++side)
        for (int k = 0; k <= 4 * g; ++k)
          for (int dir = -1; dir <= 1; dir += 2) {
            D3 o{0, 0, 0}, d{0, 0, 0};
            double* op = &o.x;
            double* dp = &d.x;
            op[plane_axis] = side;            // on the cube's (and root box's) face plane
            op[other] = k / (4.0 * g);        // on vertices, edges and between them
            op[axis] = dir > 0 ? -0.5 : 1.5;  // outside, moving in
            dp[axis] = dir;
            rays.push_back(make_ray(o, d));
            expect.push_back(0.5);
          }
    }
  auto hits = trace(s, b, rays);
  std::size_t bad = 0;
  for (std::size_t i = 0; i < rays.size(); ++i)
    if ((hits[i].prim == LC_INVALID || hits[i].t != expect[i]) && ++bad <= 5)
      ADD_FAILURE() << "ray " << i << " o=(" << rays[i].o[0] << "," << rays[i].o[1] << ","
                    << rays[i].o[2] << ") d=(" << rays[i].d[0] << "," << rays[i].d[1] << ","
                    << rays[i].d[2] << "): prim " << hits[i].prim << " t " << hits[i].t;
  EXPECT_EQ(bad, 0u);
  // and rays from inside the cube along the axes through grid vertices
  std::vector<TraceRay> in;
  for (int i = 0; i <= g; ++i)
    for (int j = 0; j <= g; ++j)
      for (int axis = 0; axis < 3; ++axis)
        for (int dir = -1; dir <= 1; dir += 2) {
          D3 o{0.5, 0.5, 0.5}, d{0, 0, 0};
          (&o.x)[(axis + 1) % 3] = i / double(g);
          (&o.x)[(axis + 2) % 3] = j / double(g);
          (&d.x)[axis] = dir;
          in.push_back(make_ray(o, d));
        }
  auto ih = trace(s, b, in);
  std::size_t escaped = 0;
  for (auto& h : ih) escaped += h.prim == LC_INVALID || h.t != 0.5f;
  EXPECT_EQ(escaped, 0u);
}

}  // namespace

namespace {

// Coincident triangles (every centroid and box the same: the build splits them by count alone)
// around the leaf limits (4 per block, 16 per leaf) and by the thousand: a ray through the
// triangle hits it, closest hit and any-hit, and one that passes outside misses (targets within
// 1e-6 of an edge are not judged).
TEST_F(BvhTrace, CoincidentTriangles) {
  for (int n : {4, 5, 16, 17, 64, 3000}) {
    Scene s;
    for (int i = 0; i < n; ++i) {
      lc_triangle t{};
      const float v[9] = {0, 0, 0.5f, 1, 0, 0.5f, 0, 1, 0.5f};
      std::memcpy(t.v0, v, 12), std::memcpy(t.v1, v + 3, 12), std::memcpy(t.v2, v + 6, 12);
      t.light = LC_INVALID;
      s.tris.push_back(t);
    }
    Bvh b = lucent::bvh::build(s.tris, s.spheres);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<TraceRay> rays;
    std::vector<int> expect;  // 1 hit, 0 miss, -1 not judged
    for (int i = 0; i < 4000; ++i) {
      const D3 o{u(rng), u(rng), -1.0}, p{u(rng) * 1.2 - 0.1, u(rng) * 1.2 - 0.1, 0.5};
      rays.push_back(make_ray(o, p - o, (i & 1) ? 2.0f : INFINITY));
      const double m = std::min({p.x, p.y, 1 - p.x - p.y});
      expect.push_back(m > 1e-6 ? 1 : (m < -1e-6 ? 0 : -1));
    }
    for (bool any : {false, true}) {
      auto h = trace(s, b, rays, any);
      std::size_t bad = 0, hits = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        hits += h[i].prim != LC_INVALID;
        if (expect[i] >= 0 && (h[i].prim != LC_INVALID) != (expect[i] == 1)) ++bad;
        if (!any && h[i].prim != LC_INVALID) {
          EXPECT_NEAR(h[i].t, 1.5 / rays[i].d[2], 1e-5) << n;
        }
      }
      EXPECT_EQ(bad, 0u) << n << " triangles, any-hit " << any;
      EXPECT_GT(hits, rays.size() / 4) << n;
    }
  }
}

}  // namespace

}  // namespace test_bvh_trace
