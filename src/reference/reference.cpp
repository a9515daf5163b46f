// Reference integrator: camera, filters, lights and every integrator of docs/rendering-model.md,
// in double precision, one camera sample at a time. Written to be read and checked against the
// model, not to be fast. Its sampling strategies deliberately differ from the kernel's where the
// model allows it (uniform light selection, uniform area sampling of spheres, uniform sphere
// sampling of the environment, tent filter as a sum of two uniforms, Gaussian filter by
// rejection, polar lens sampling), so that a pdf mistake on either side shows up as a difference
// of expected values.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "lucent/error.hpp"
#include "lucent/reference.hpp"
#include "reference/reference_internal.hpp"
#include "shared/rng.h"

namespace lucent {

namespace ref {

namespace {

/// Random numbers of one camera sample: the kernel's counter-based generator and dimension layout.
struct Sampler {
  std::uint32_t pixel, sample, seed;
  double get(std::uint32_t dim) const { return lc_rng_uniform(pixel, sample, dim, seed); }
  double bounce(int depth, std::uint32_t offset) const {
    return get(LC_DIM_BOUNCE + static_cast<std::uint32_t>(depth) * LC_DIMS_PER_BOUNCE + offset);
  }
};

/// Dimensions beyond any bounce's, for the filters' extra numbers.
constexpr std::uint32_t kDimExtra = 0x40000000u;

/// Rays traced by the calling thread.
thread_local std::uint64_t t_rays = 0;

struct CameraFrame {
  dvec3 pos, right, up, fwd;
  double tan_half = 0, aspect = 1, lens = 0, focus = 0;
  int width = 1, height = 1;
};

class Renderer {
 public:
  explicit Renderer(const Scene& s) : scene_(s), world_(s) {
    lights_ = light_list(world_, env_);
    setup_camera();
  }

  /// One camera sample; adds the rays it traces to t_rays.
  dvec3 sample_pixel(int x, int y, const Sampler& rng) const {
    Ray ray = camera_ray(x, y, rng);
    switch (scene_.integrator.type) {
      case IntegratorType::Path: return path(ray, rng);
      case IntegratorType::Whitted: return whitted(ray, 0, dvec3(1.0));
      case IntegratorType::Direct: return direct(ray);
      case IntegratorType::Albedo:
      case IntegratorType::Normal:
      case IntegratorType::Depth:
      case IntegratorType::Ao:
      case IntegratorType::Primitive: return aov(ray, rng);
    }
    return dvec3(0.0);
  }

 private:
  const Scene& scene_;
  World world_;
  std::vector<LightRef> lights_;
  int env_ = -1;
  CameraFrame cam_;

  // ----------------------------------------------------------------------------------------
  // camera and filters

  void setup_camera() {
    const Camera& c = scene_.camera;
    cam_.pos = c.position;
    cam_.fwd = glm::normalize(c.look_at - c.position);
    dvec3 right = glm::normalize(glm::cross(cam_.fwd, c.up));
    dvec3 up = glm::cross(right, cam_.fwd);
    // roll: right and up turn counter-clockwise as seen looking along forward, i.e. right moves
    // towards up
    double r = c.roll_degrees * kPi / 180;
    cam_.right = std::cos(r) * right + std::sin(r) * up;
    cam_.up = -std::sin(r) * right + std::cos(r) * up;
    cam_.width = scene_.film.width;
    cam_.height = scene_.film.height;
    cam_.tan_half = std::tan(c.fov_degrees * kPi / 360);
    cam_.aspect = double(cam_.width) / cam_.height;
    cam_.lens = c.aperture;
    cam_.focus = c.focus_distance > 0 ? c.focus_distance : glm::length(c.look_at - c.position);
  }

  /// Offset of a sample from the pixel centre, drawn from the filter.
  dvec2 filter_offset(const Sampler& rng) const {
    const Filter& f = scene_.film.filter;
    double r = f.radius;
    switch (f.type) {
      case FilterType::Box:
        return dvec2((2 * rng.get(LC_DIM_FILTER) - 1) * r, (2 * rng.get(LC_DIM_FILTER + 1) - 1) * r);
      case FilterType::Tent:
        // the sum of two uniforms on [0, r] minus r has density (r - |t|) / r^2 on [-r, r]
        return dvec2(r * (rng.get(LC_DIM_FILTER) + rng.get(kDimExtra) - 1),
                     r * (rng.get(LC_DIM_FILTER + 1) + rng.get(kDimExtra + 1) - 1));
      case FilterType::Gaussian: {
        // 2D normal (Box-Muller) with sigma = r / 3, rejected outside the disk of radius r
        double sigma = r / 3;
        for (std::uint32_t k = 0; k < 64; ++k) {
          double u1 = k == 0 ? rng.get(LC_DIM_FILTER) : rng.get(kDimExtra + 2 * k);
          double u2 = k == 0 ? rng.get(LC_DIM_FILTER + 1) : rng.get(kDimExtra + 2 * k + 1);
          double rho = sigma * std::sqrt(-2 * std::log(1 - u1)), phi = 2 * kPi * u2;
          if (rho <= r) return dvec2(rho * std::cos(phi), rho * std::sin(phi));
        }
        return dvec2(0.0);  // (0.011)^64: never
      }
    }
    return dvec2(0.0);
  }

  Ray camera_ray(int x, int y, const Sampler& rng) const {
    dvec2 off = filter_offset(rng);
    double fx = x + 0.5 + off.x, fy = y + 0.5 + off.y;
    double ndc_x = (2 * fx / cam_.width - 1) * cam_.tan_half * cam_.aspect;
    double ndc_y = (1 - 2 * fy / cam_.height) * cam_.tan_half;
    Ray ray{cam_.pos, glm::normalize(cam_.fwd + ndc_x * cam_.right + ndc_y * cam_.up)};
    if (cam_.lens > 0) {
      dvec3 focus = cam_.pos + (cam_.focus / glm::dot(ray.d, cam_.fwd)) * ray.d;
      double lr = cam_.lens * std::sqrt(rng.get(LC_DIM_LENS)), phi = 2 * kPi * rng.get(LC_DIM_LENS + 1);
      ray.o = cam_.pos + lr * std::cos(phi) * cam_.right + lr * std::sin(phi) * cam_.up;
      ray.d = glm::normalize(focus - ray.o);
    }
    return ray;
  }

  // ----------------------------------------------------------------------------------------
  // scene queries

  bool trace(const Ray& r, Hit& h) const {
    ++t_rays;
    return world_.intersect(r, kInf, h);
  }
  bool blocked(const Ray& r, double tmax, int skip = -1) const {
    ++t_rays;
    return world_.occluded(r, tmax, skip);
  }

  static Ray spawn(const Surface& s, const dvec3& wi) {
    double side = glm::dot(wi, s.ng) > 0 ? 1 : -1;
    return Ray{s.p + side * s.err * s.ng, wi};
  }

  /// Radiance of a ray that leaves the scene.
  dvec3 environment(const dvec3& d) const {
    if (env_ < 0) return dvec3(0.0);
    const Light& l = scene_.lights[env_];
    if (l.type == LightType::Environment) return l.radiance;
    if (l.texture < 0 || l.texture >= static_cast<int>(scene_.textures.size())) return dvec3(0.0);
    const Texture& t = scene_.textures[l.texture];
    if (t.width <= 0 || t.height <= 0) return dvec3(0.0);
    double u = 0.5 + std::atan2(d.x, -d.z) / (2 * kPi);
    double v = std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi;
    int x = std::clamp(static_cast<int>(std::floor(u * t.width)), 0, t.width - 1);
    int y = std::clamp(static_cast<int>(std::floor(v * t.height)), 0, t.height - 1);
    const float* px = &t.rgba[(static_cast<size_t>(y) * t.width + x) * 4];
    return l.radiance * dvec3(px[0], px[1], px[2]);
  }

  const Material& material(const Surface& s) const { return scene_.materials[s.material]; }

  dvec3 emitted(const Surface& s) const { return s.front ? material(s).emission : dvec3(0.0); }

  static double power_heuristic(double a, double b) {
    if (std::isinf(a)) return 1;
    return a * a / (a * a + b * b);
  }

  /// Point-light illumination through the full BSDF.
  dvec3 point_lights(const Surface& s, const Bsdf& b, const dvec3& wo) const {
    dvec3 sum(0.0);
    for (const Light& l : scene_.lights) {
      if (l.type != LightType::Point) continue;
      sum += point_light(s, b, wo, l);
    }
    return sum;
  }

  dvec3 point_light(const Surface& s, const Bsdf& b, const dvec3& wo, const Light& l) const {
    dvec3 to = l.position - s.p;
    double d2 = glm::dot(to, to);
    if (d2 <= 0) return dvec3(0.0);
    dvec3 wi = to / std::sqrt(d2);
    dvec3 f = b.eval(wo, wi);
    if (max3(f) <= 0) return dvec3(0.0);
    Ray r = spawn(s, wi);
    if (blocked(r, glm::length(l.position - r.o) * (1 - 1e-9))) return dvec3(0.0);
    return f * l.intensity / d2;
  }

  /// Next-event estimation: one light chosen uniformly, MIS-weighted against BSDF sampling.
  dvec3 sample_light(const Surface& s, const Bsdf& b, const dvec3& wo, const Sampler& rng,
                     int depth) const {
    if (lights_.empty()) return dvec3(0.0);
    const double n = static_cast<double>(lights_.size());
    LightSample ls = ref::sample_light(world_, lights_, s.p, rng.bounce(depth, LC_DIM_LIGHT_SELECT),
                                       rng.bounce(depth, LC_DIM_LIGHT_UV),
                                       rng.bounce(depth, LC_DIM_LIGHT_UV + 1));
    const LightRef& lr = lights_[ls.light];
    if (lr.kind == LightRef::Point) return n * point_light(s, b, wo, scene_.lights[lr.index]);
    if (!ls.valid) return dvec3(0.0);
    const dvec3& wi = ls.wi;
    dvec3 f = b.eval(wo, wi);
    if (max3(f) <= 0) return dvec3(0.0);
    if (lr.kind == LightRef::Env) {
      dvec3 Le = environment(wi);
      if (max3(Le) <= 0) return dvec3(0.0);
      if (blocked(spawn(s, wi), kInf)) return dvec3(0.0);
      return f * Le * power_heuristic(ls.pdf, b.pdf(wo, wi)) / ls.pdf;
    }
    const AreaLight& al = world_.area_lights[lr.index];
    // The light's own primitive cannot hide a point of it that faces us (a sphere is convex), so
    // it is left out of the shadow test: near its silhouette, the ray from the offset origin
    // would otherwise graze it just before the sampled point.
    Ray r = spawn(s, wi);
    if (blocked(r, glm::length(ls.y - r.o) * (1 - 1e-7), al.prim)) return dvec3(0.0);
    const Prim& p = world_.prims[al.prim];
    int mat = p.sphere ? scene_.spheres[p.index].material : scene_.triangles[p.index].material;
    return f * scene_.materials[mat].emission * power_heuristic(ls.pdf, b.pdf(wo, wi)) / ls.pdf;
  }

  // ----------------------------------------------------------------------------------------
  // integrators

  dvec3 path(Ray ray, const Sampler& rng) const {
    const Integrator& in = scene_.integrator;
    dvec3 L(0.0), beta(1.0);
    double prev_pdf = 0;     // BSDF pdf of the previous direction
    bool prev_delta = true;  // camera rays and delta bounces: no MIS on what they hit
    for (int depth = 0;; ++depth) {
      Hit hit;
      if (!trace(ray, hit)) {
        dvec3 Le = environment(ray.d);
        double w = 1;
        if (!prev_delta && env_ >= 0) w = power_heuristic(prev_pdf, env_light_pdf(lights_.size()));
        L += beta * Le * w;
        break;
      }
      Surface s = world_.surface(ray, hit);
      dvec3 Le = emitted(s);
      if (max3(Le) > 0) {
        double w = 1;
        if (!prev_delta)
          w = power_heuristic(prev_pdf, area_light_pdf(world_, lights_.size(), s.prim, hit.t,
                                                       glm::dot(s.ng, -ray.d)));
        L += beta * Le * w;
      }
      if (depth + 1 >= in.max_depth) break;
      dvec3 wo = -ray.d;
      Bsdf b = make_bsdf(scene_, s);
      if (!b.is_delta()) L += beta * sample_light(s, b, wo, rng, depth);
      BsdfSample bs = b.sample(wo, rng.bounce(depth, LC_DIM_BSDF_LOBE),
                               rng.bounce(depth, LC_DIM_BSDF_UV), rng.bounce(depth, LC_DIM_BSDF_UV + 1));
      if (!bs.valid) break;
      beta *= bs.weight;
      prev_pdf = bs.pdf;
      prev_delta = bs.delta;
      ray = spawn(s, bs.wi);
      if (depth + 1 >= in.rr_depth) {
        double q = std::min(0.95, max3(beta));
        if (rng.bounce(depth, LC_DIM_RR) >= q) break;
        beta /= q;
      }
    }
    return L;
  }

  dvec3 direct(const Ray& ray) const {
    Hit hit;
    if (!trace(ray, hit)) return environment(ray.d);
    Surface s = world_.surface(ray, hit);
    Bsdf b = make_bsdf(scene_, s);
    return emitted(s) + point_lights(s, b, -ray.d);
  }

  dvec3 whitted(const Ray& ray, int depth, const dvec3& throughput) const {
    Hit hit;
    if (!trace(ray, hit)) return environment(ray.d);
    Surface s = world_.surface(ray, hit);
    dvec3 L = emitted(s);
    if (depth + 1 >= scene_.integrator.max_depth) return L;
    // branches too faint to matter are cut (the only departure from the exact recursion)
    if (max3(throughput) < 1e-9) return L;
    const Material& m = material(s);
    Bsdf b = make_bsdf(scene_, s);
    dvec3 wo = -ray.d;
    double co = glm::dot(wo, s.ns);
    dvec3 refl = glm::normalize(2 * co * s.ns - wo);
    auto reflected = [&](const dvec3& w) {
      if (glm::dot(refl, s.ng) <= 0) return dvec3(0.0);
      return whitted(spawn(s, refl), depth + 1, throughput * w);
    };
    auto diffuse_term = [&]() {
      dvec3 sum(0.0);
      for (const Light& l : scene_.lights) {
        if (l.type != LightType::Point) continue;
        dvec3 to = l.position - s.p;
        double d2 = glm::dot(to, to);
        dvec3 wi = to / std::sqrt(d2);
        double c = glm::dot(wi, s.ns);
        if (c <= 0 || glm::dot(wi, s.ng) <= 0) continue;
        Ray r = spawn(s, wi);
        if (blocked(r, glm::length(l.position - r.o) * (1 - 1e-9))) continue;
        sum += l.intensity * c / d2;
      }
      return b.albedo / kPi * sum;
    };
    switch (m.type) {
      case MaterialType::Diffuse:
        L += diffuse_term();
        break;
      case MaterialType::Mirror:
      case MaterialType::Conductor:
        L += m.specular * reflected(m.specular);
        break;
      case MaterialType::Plastic: {
        L += diffuse_term();
        dvec3 w = reference::fresnel_dielectric(co, m.ior) * m.specular;
        L += w * reflected(w);
        break;
      }
      case MaterialType::Dielectric: {
        if (co <= 0) break;
        double eta = s.front ? m.ior : 1 / m.ior;
        double F = reference::fresnel_dielectric(co, eta);
        L += F * whitted(spawn(s, refl), depth + 1, throughput * F);
        if (F < 1) {
          double cos_t = std::sqrt(std::max(0.0, 1 - (1 - co * co) / (eta * eta)));
          dvec3 wt = glm::normalize(-wo / eta + (co / eta - cos_t) * s.ns);
          dvec3 w = (1 - F) * m.specular;
          L += w * whitted(spawn(s, wt), depth + 1, throughput * w);
        }
        break;
      }
    }
    return L;
  }

  dvec3 aov(const Ray& ray, const Sampler& rng) const {
    Hit hit;
    if (!trace(ray, hit)) return dvec3(0.0);
    Surface s = world_.surface(ray, hit);
    switch (scene_.integrator.type) {
      case IntegratorType::Albedo: {
        const Material& m = material(s);
        if (m.type == MaterialType::Diffuse || m.type == MaterialType::Plastic)
          return make_bsdf(scene_, s).albedo;
        return m.specular;
      }
      case IntegratorType::Normal:
        return s.ns;
      case IntegratorType::Depth:
        return dvec3(hit.t);
      case IntegratorType::Primitive: {  // spheres first, then the scene's triangle list
        const Prim& p = world_.prims[hit.prim];
        return dvec3(double((p.sphere ? 0 : scene_.spheres.size()) + p.index + 1));
      }
      default: {  // ambient occlusion
        double u1 = rng.bounce(0, LC_DIM_BSDF_UV), u2 = rng.bounce(0, LC_DIM_BSDF_UV + 1);
        dvec3 a = std::abs(s.ns.x) > 0.5 ? dvec3(0, 1, 0) : dvec3(1, 0, 0);
        dvec3 t = glm::normalize(glm::cross(a, s.ns)), bt = glm::cross(s.ns, t);
        double r = std::sqrt(u1), phi = 2 * kPi * u2;
        dvec3 wi = glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * bt +
                                  std::sqrt(std::max(0.0, 1 - u1)) * s.ns);
        if (glm::dot(wi, s.ng) <= 0) return dvec3(0.0);  // into the surface itself
        double dist = scene_.integrator.ao_distance > 0 ? scene_.integrator.ao_distance : kInf;
        return blocked(spawn(s, wi), dist) ? dvec3(0.0) : dvec3(1.0);
      }
    }
  }
};

}  // namespace

std::vector<LightRef> light_list(const World& world, int& env) {
  std::vector<LightRef> lights;
  env = -1;
  for (size_t i = 0; i < world.scene.lights.size(); ++i) {
    if (world.scene.lights[i].type == LightType::Point) {
      lights.push_back({LightRef::Point, static_cast<int>(i)});
    } else {
      env = static_cast<int>(i);
      lights.push_back({LightRef::Env, static_cast<int>(i)});
    }
  }
  for (size_t i = 0; i < world.area_lights.size(); ++i)
    lights.push_back({LightRef::Area, static_cast<int>(i)});
  return lights;
}

double area_light_pdf(const World& world, size_t nlights, int prim, double dist, double cos_l) {
  int li = world.prim_light[prim];
  if (li < 0 || cos_l <= 0) return 0;
  return dist * dist / (cos_l * world.area_lights[li].area * nlights);
}

LightSample sample_light(const World& world, const std::vector<LightRef>& lights, const dvec3& p,
                         double u_select, double u1, double u2) {
  LightSample ls;
  if (lights.empty()) return ls;
  const double n = static_cast<double>(lights.size());
  ls.light = static_cast<int>(std::min(lights.size() - 1, static_cast<size_t>(u_select * n)));
  const LightRef& lr = lights[ls.light];
  if (lr.kind == LightRef::Point) {
    dvec3 to = world.scene.lights[lr.index].position - p;
    ls.dist = glm::length(to);
    ls.delta = true;
    ls.pdf = 1 / n;
    ls.valid = ls.dist > 0;
    if (ls.valid) ls.wi = to / ls.dist;
    return ls;
  }
  if (lr.kind == LightRef::Env) {
    // uniform direction on the sphere
    double z = 1 - 2 * u1, rr = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u2;
    ls.wi = dvec3(rr * std::cos(phi), rr * std::sin(phi), z);
    ls.pdf = env_light_pdf(lights.size());
    ls.valid = true;
    return ls;
  }
  const AreaLight& al = world.area_lights[lr.index];
  world.sample_area(al.prim, u1, u2, ls.y, ls.ny);
  dvec3 to = ls.y - p;
  ls.dist = glm::length(to);
  if (ls.dist <= 0) return ls;
  ls.wi = to / ls.dist;
  double cos_l = -glm::dot(ls.ny, ls.wi);  // > 0: the point's front side faces us
  if (cos_l <= 0) return ls;
  ls.pdf = area_light_pdf(world, lights.size(), al.prim, ls.dist, cos_l);
  ls.valid = true;
  return ls;
}

}  // namespace ref

RenderResult render_reference(const Scene& scene, const ReferenceOptions& options) {
  const int W = scene.film.width, H = scene.film.height;
  if (W <= 0 || H <= 0) throw Error(scene.path + ": film size must be positive");
  const int spp = options.spp > 0 ? options.spp : scene.integrator.spp;
  if (spp <= 0) throw Error(scene.path + ": samples per pixel must be positive");
  auto t0 = std::chrono::steady_clock::now();
  ref::Renderer renderer(scene);

  const size_t npix = static_cast<size_t>(W) * H;
  std::vector<double> mean(npix * 3, 0.0), m2(npix * 3, 0.0);
  std::vector<std::uint32_t> count(npix, 0);
  std::atomic<int> next_row{0};
  std::atomic<std::uint64_t> nonfinite{0}, rays{0};
  std::atomic<bool> cancelled{false};

  auto worker = [&]() {
    ref::t_rays = 0;
    std::uint64_t my_nonfinite = 0;
    for (int y; (y = next_row.fetch_add(1)) < H;) {
      if (options.cancel && options.cancel->load()) {
        cancelled = true;
        break;
      }
      for (int x = 0; x < W; ++x) {
        const size_t i = static_cast<size_t>(y) * W + x;
        for (int k = 0; k < spp; ++k) {
          ref::Sampler rng{static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(k),
                           scene.integrator.seed};
          glm::dvec3 v = renderer.sample_pixel(x, y, rng);
          if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
            ++my_nonfinite;
            continue;
          }
          // Welford's running mean and sum of squared deviations
          double n = ++count[i];
          for (int c = 0; c < 3; ++c) {
            double d = v[c] - mean[i * 3 + c];
            mean[i * 3 + c] += d / n;
            m2[i * 3 + c] += d * (v[c] - mean[i * 3 + c]);
          }
        }
      }
    }
    rays += ref::t_rays;
    nonfinite += my_nonfinite;
  };
  int threads = options.threads > 0 ? options.threads
                                    : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  threads = std::min(threads, H);
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();

  RenderResult r;
  r.mean = Image{W, H, std::vector<float>(npix * 3)};
  r.variance = Image{W, H, std::vector<float>(npix * 3)};
  for (size_t i = 0; i < npix; ++i)
    for (int c = 0; c < 3; ++c) {
      r.mean.rgb[i * 3 + c] = static_cast<float>(mean[i * 3 + c]);
      r.variance.rgb[i * 3 + c] =
          static_cast<float>(count[i] > 1 ? m2[i * 3 + c] / (count[i] - 1) : 0.0);
    }
  r.samples = std::move(count);
  r.spp = static_cast<std::uint64_t>(spp);
  r.nonfinite = nonfinite;
  r.rays = rays;
  r.cancelled = cancelled;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.device = "reference (" + std::to_string(threads) + " thread" + (threads > 1 ? "s" : "") + ")";
  return r;
}

}  // namespace lucent
